#!/usr/bin/env python3
"""Writes data/fiv_instances50.json: 50 dynamic occluders for `prtview --instances`, copies of the
three occluders of data/scene_fiv_occluders.json (20 bunnies, 15 spiders, 15 statues), each moved
from where it was baked (standing on y = 0 at the origin) to a cell of a jittered 8 x 8 grid of
10-unit cells, jittered by up to 0.5 (no two copies overlap). 36 stand on the ground (y offset 0: their lowest points touch
it); 14 float 0.5 to 4 units above it, as thrown or falling objects would.
Deterministic (a fixed linear congruential sequence, no library RNG). Run from the repository root:
python3 data/make_fiv_instances.py
"""
import json
import pathlib

state = 12345
def rand():
    global state
    state = (1103515245 * state + 12345) % 2**31
    return state / 2**31

cells = [(i, j) for j in range(8) for i in range(8)]
for k in range(len(cells) - 1, 0, -1):  # Fisher-Yates with the sequence above
    m = int(rand() * (k + 1))
    cells[k], cells[m] = cells[m], cells[k]
kinds = ["bunny"] * 20 + ["spider"] * 15 + ["statue"] * 15
instances = []
for n, (kind, (i, j)) in enumerate(zip(kinds, cells)):
    x = -35 + 10 * i + (rand() - 0.5) * 1.0
    z = -35 + 10 * j + (rand() - 0.5) * 1.0
    y = 0.0 if n % 25 < 18 else round(0.5 + 3.5 * rand(), 3)
    instances.append({"occluder": kind, "translate": [round(x, 3), y, round(z, 3)]})
out = pathlib.Path(__file__).resolve().parent / "fiv_instances50.json"
lines = ",\n".join("  " + json.dumps(i) for i in instances)
out.write_text('{\n "instances": [\n' + lines + "\n ]\n}\n")
print(f"wrote {out}: {len(instances)} instances, {sum(1 for i in instances if i['translate'][1] == 0)} on the ground")
