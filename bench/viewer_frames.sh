#!/usr/bin/env bash
# bench/viewer_frames.sh — the web viewer's frame time against mesh size (bench/RESULTS.md "Web
# viewer"): the bunny split 1 -> 4 per level (each triangle into four at its edge midpoints; the
# shape unchanged, 3,674 to 235,136 triangles) and the CAD engine, each baked (AO + transfer
# order 3, QMC 16 rays), exported --to web and drawn in headless Chromium (SwiftShader, 640x480,
# the environment turning a degree a frame, each frame waited for) by viewer/test/browser_test.mjs.
#   bench/viewer_frames.sh [BUILD_DIR]     (default build/release; needs viewer/node_modules: npm ci)
set -euo pipefail
cd "$(dirname "$0")/.."
B=${1:-build/release}/tools
OUT=${OUT:-/tmp/prt_viewer_frames}
ENGINE=${ENGINE:-/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb}
mkdir -p "$OUT"
python3 - "$OUT" <<'PY'
import sys
out = sys.argv[1]
V, F = [], []
for line in open('data/bunny.obj'):
    t = line.split()
    if t and t[0] == 'v': V.append(tuple(map(float, t[1:4])))
    if t and t[0] == 'f': F.append(tuple(int(x.split('/')[0]) - 1 for x in t[1:4]))
for level in range(4):
    with open(f'{out}/bunny_x{4 ** level}.obj', 'w') as f:
        f.writelines(f'v {x!r} {y!r} {z!r}\n' for x, y, z in V)
        f.writelines(f'f {a + 1} {b + 1} {c + 1}\n' for a, b, c in F)
    mid, F2 = {}, []
    def m(a, b):
        k = (min(a, b), max(a, b))
        if k not in mid:
            mid[k] = len(V)
            V.append(tuple((p + q) / 2 for p, q in zip(V[a], V[b])))
        return mid[k]
    for a, b, c in F:
        ab, bc, ca = m(a, b), m(b, c), m(c, a)
        F2 += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
    F = F2
PY
MESHES=$(ls "$OUT"/bunny_x*.obj | sort -V | tr '\n' ,)$ENGINE
nice node viewer/test/browser_test.mjs --prtbake "$B/prtbake" --prtview "$B/prtview" --data data --engine "$ENGINE" \
  --out "$OUT/run" --sweep "$MESHES"
