#!/usr/bin/env node
// viewer/test/browser_test.mjs — the web viewer in a real browser (issue 34; ctest viewer_browser).
//
// For the bunny on its ground, the statue (wuson.obj, the statue of data/scene_example.json) and
// the CAD engine (2CylinderEngine.glb): bake AO + diffuse transfer (order 3), `prtbake export
// --to web`, then in Debian's Chromium (headless, WebGL through SwiftShader, driven by
// puppeteer-core: no browser download) render prtview's first-look camera at three environment
// rotations and compare each picture with `prtview --shade transfer --env-rotate DEG` of the same
// view at the same exposure. Both are 8-bit sRGB; NRMSE = RMSE over the pixels either covers and
// the three channels / the reference's range there (view/image.h's definition).
//   The two compute the same per-vertex colours (the same formulas, float in both) and interpolate
//   them perspective-correctly with the same pixel-centre rule; what differs is which triangle
//   owns a pixel centre that lies within rounding of an edge or a depth tie: prtview decides it
//   with double edge functions, SwiftShader at its fixed-point sub-pixel precision. So:
//   kMaxNrmse = 0.01 (the bound) over the pixels inside both silhouettes (each pixel and
//   its 8 neighbours covered in both pictures), for the bunny and the statue; what is left there is
//   8-bit rounding (±1 level) and the odd pixel on a crease. The engine's fins and bolts are finer
//   than a pixel and its parts interpenetrate, so inside its silhouettes whole pixels still go to
//   another triangle across a hard edge: measured 0.031 at 320x240, 0.018 at 640x480 (halving the
//   pixel halves the share of such pixels): kMaxNrmseEngine = 0.02 at 640x480.
//   kMaxNrmseAll = 0.04 over every pixel either covers: the silhouette band, where a pixel is
//   surface in one picture and background in the other, is 2-11% of the covered pixels at these
//   sizes (0.012-0.029 measured). A wrong rotation, a shifted camera or a wrong formula shows as
//   0.1 and more in both figures.
// Also compared: glossy lobes by route B (a glossy statue, prtview --shade glossy, at the file's
// Phong exponent and at 128) and two area lights with a spot and a sun (prtview --shade area). The bunny, baked with
// band-1 radiance too, is compared in that mode as well (prtview --shade band1,
// the same bounds); so is the bunny baked per texel (prtbake texel, a 256x256 lightmap), which
// both draw per pixel from the lightmap. Also: a glb that is not one and a file without the product asked for show a message in the page
// (not a blank canvas), and the frame time per asset (640x480, the environment turning one degree
// a frame, each frame waited for) is printed. Exit 0 pass, 1 fail, 77 when Chromium cannot start
// (ctest SKIP_RETURN_CODE).
//
// node browser_test.mjs --prtbake B --prtview V --data DIR --engine GLB --out DIR [--images DIR]
//   --images DIR also writes the README's pictures (docs/images/viewer_<asset>.png: the page with the
//   unshadowed surface side by side, 960x360).
// node browser_test.mjs ... --sweep MESH,MESH,...   only the frame times of these meshes (AO and
//   transfer order 3 by QMC at 16 rays: the page's cost does not depend on the bake's quality);
//   bench/viewer_frames.sh runs it.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';

const SKIP = 77;
const kMaxNrmse = 0.01, kMaxNrmseEngine = 0.02, kMaxNrmseAll = 0.04;
const kRotations = [0, 120, 240];
const kSize = '320x240';

const opt = {};
for (let i = 2; i < process.argv.length; i += 2) opt[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
for (const k of ['prtbake', 'prtview', 'data', 'engine', 'out'])
  if (!opt[k]) { console.error(`browser_test: --${k} is required`); process.exit(2); }

let puppeteer;
try {
  puppeteer = (await import('puppeteer-core')).default;
} catch (e) {
  console.error(`browser_test: puppeteer-core is not installed (npm ci in viewer/, as tools/run.sh does): ${e.message}`);
  process.exit(1);
}

function run(cmd, argv) {
  const r = spawnSync(cmd, argv, { encoding: 'utf8', maxBuffer: 1 << 26 });
  if (r.status !== 0) throw new Error(`${path.basename(cmd)} ${argv.join(' ')}: exit ${r.status}\n${r.stderr}${r.error || ''}`);
  return r.stdout + r.stderr;
}

for (const f of [opt.prtbake, opt.prtview, opt.engine])
  if (!fs.existsSync(f)) { console.error(`browser_test: ${f} does not exist${f === opt.engine ? ' (Debian package assimp-testmodels)' : ''}`); process.exit(1); }
const out = path.resolve(opt.out);
fs.rmSync(out, { recursive: true, force: true });
fs.mkdirSync(out, { recursive: true });
const sunset = path.join(opt.data, 'sunset.exr');
const sweep = opt.sweep ? opt.sweep.split(',').map((m, k) => ({ name: `sweep${k}`, mesh: m, samples: 16, extra: [], framesOnly: true })) : null;
const assets = sweep || [
  { name: 'bunny', mesh: path.join(opt.data, 'bunny_ground.obj'), samples: 256, extra: ['--radiance', sunset] },
  { name: 'statue', mesh: path.join(opt.data, 'wuson.obj'), samples: 256, extra: [] },
  { name: 'engine', mesh: opt.engine, samples: 64, extra: [], size: '640x480', maxInterior: kMaxNrmseEngine },
  // Per texel: the bunny alone with a generated 256x256 lightmap (prtbake texel), drawn per pixel
  // from it by both (SCHEMA's bilinear rule).
  { name: 'bunny_texel', mesh: path.join(opt.data, 'bunny.obj'), samples: 64, extra: ['--radiance', sunset], texel: '256' },
];

// Chromium first: without it there is nothing to test (skip, saying why).
let browser;
const chromium = process.env.PRT_CHROMIUM || '/usr/bin/chromium';
try {
  if (!fs.existsSync(chromium)) throw new Error(`${chromium} does not exist (Debian package chromium)`);
  browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--disable-gpu-vsync'],
  });
} catch (e) {
  console.log(`SKIP: Chromium cannot start: ${e.message.split('\n')[0]}`);
  process.exit(SKIP);
}

const types = { '.html': 'text/html', '.js': 'text/javascript', '.json': 'application/json', '.png': 'image/png', '.glsl': 'text/plain', '.inc': 'text/plain' };
const server = http.createServer((req, res) => {
  const rel = decodeURIComponent(new URL(req.url, 'http://localhost').pathname);
  const file = path.join(out, rel.endsWith('/') ? rel + 'index.html' : rel);
  if (!file.startsWith(out)) { res.writeHead(403); res.end(); return; }
  fs.readFile(file, (err, data) => {
    if (err) { res.writeHead(404); res.end(); return; }
    res.writeHead(200, { 'Content-Type': types[path.extname(file)] || 'application/octet-stream' });
    res.end(data);
  });
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const base = `http://127.0.0.1:${server.address().port}`;

// Opens a page of an export; returns { page, ready, error, message (the text shown) }.
async function open(dir, query, viewport = { width: 1000, height: 700 }) {
  const page = await browser.newPage();
  await page.setViewport(viewport);
  const logs = [];
  page.on('console', (m) => logs.push(m.text()));
  page.on('pageerror', (e) => logs.push(String(e)));
  await page.goto(`${base}/${dir}/index.html?${query}`);
  await page.waitForFunction('window.prtViewer && (window.prtViewer.ready || window.prtViewer.error)', { timeout: 60000 });
  const s = await page.evaluate(() => ({
    ready: window.prtViewer.ready,
    error: window.prtViewer.error,
    message: getComputedStyle(document.getElementById('message')).display !== 'none' ? document.getElementById('message').textContent : '',
  }));
  return { page, logs, ...s };
}

const failures = [];
const check = (ok, what) => {
  if (!ok) failures.push(what);
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${what}`);
};
const rows = [], frames = [];
try {
  for (const a of assets) {
    const t0 = Date.now();
    const h5 = path.join(out, `${a.name}.prt.h5`);
    run(opt.prtbake, [a.texel ? 'texel' : 'vertex', a.mesh, ...(a.texel ? ['--resolution', a.texel] : []), '--ao', '--transfer', '3',
                      ...a.extra, '--integrator', 'qmc', '--samples', String(a.samples), '--report', '0', '--reproducible', '-q', '-o', h5]);
    run(opt.prtbake, ['export', h5, '--to', 'web', '--env', sunset, '-o', path.join(out, a.name)]);
    const info = JSON.parse(fs.readFileSync(path.join(out, a.name, 'viewer.json'), 'utf8'));
    const exposure = info.environments.find((e) => e.name === 'sunset.exr').exposure;
    // prtview's first look chooses the camera; both renderers then use it.
    const size = a.size || kSize;
    const look = run(opt.prtview, [h5, '--shade', 'transfer', '--env', sunset, '--size', size, '-o', path.join(out, `${a.name}_look.png`)]);
    const camera = look.match(/--camera (\S+)/)[1];
    fs.writeFileSync(path.join(out, `${a.name}_camera.txt`), camera);
    const vertices = info.file.vertex_sets.reduce((n, s) => n + s.vertices, 0);
    const triangles = info.file.vertex_sets.reduce((n, s) => n + (s.triangles || 0), 0);
    for (const deg of a.framesOnly ? [] : kRotations) {
      const ref = `ref_${deg}.png`;
      run(opt.prtview, [h5, '--shade', 'transfer', '--env', sunset, '--size', size, '--camera', camera, '--exposure', String(exposure),
                        '--env-rotate', String(deg), '-q', '-o', path.join(out, a.name, ref)]);
      const q = new URLSearchParams({ mode: 'transfer', env: 'sunset.exr', rotate: deg, exposure, camera, size });
      const p = await open(a.name, q.toString());
      check(p.ready && !p.error, `${a.name} at ${deg} deg: the page draws (${p.error || 'no error'})`);
      if (p.ready) {
        const c = await p.page.evaluate((u) => window.prtViewer.compare(u), ref);
        const png = await p.page.evaluate(() => window.prtViewer.png());
        fs.writeFileSync(path.join(out, a.name, `page_${deg}.png`), Buffer.from(png.split(',')[1], 'base64'));
        rows.push({ asset: a.name, deg, vertices, triangles, ...c });
        const bound = a.maxInterior || kMaxNrmse;
        check(c.nrmse_interior <= bound, `${a.name} at ${deg} deg: NRMSE ${c.nrmse_interior.toFixed(5)} <= ${bound} against prtview inside ` +
                                   `both silhouettes (${c.interior_pixels} px)`);
        check(c.nrmse <= kMaxNrmseAll, `${a.name} at ${deg} deg: NRMSE ${c.nrmse.toFixed(5)} <= ${kMaxNrmseAll} over all ${c.pixels} covered px ` +
                                   `(max |diff| ${c.max_abs}/255, ${c.pixels_off_by_more_than_2} px off by more than 2)`);
      }
      await p.page.close();
    }
    if (a.extra.includes('--radiance')) {  // band-1 radiance: the baked sky, prtview --shade band1
      run(opt.prtview, [h5, '--shade', 'band1', '--size', size, '--camera', camera, '--exposure', String(exposure), '-q',
                        '-o', path.join(out, a.name, 'ref_band1.png')]);
      const p = await open(a.name, new URLSearchParams({ mode: 'band1', exposure, camera, size }).toString());
      const c = p.ready ? await p.page.evaluate((u) => window.prtViewer.compare(u), 'ref_band1.png') : { nrmse_interior: 1, nrmse: 1 };
      rows.push({ asset: a.name, deg: 'band-1', vertices, triangles, ...c });
      check(c.nrmse_interior <= kMaxNrmse && c.nrmse <= kMaxNrmseAll,
            `${a.name} band-1 radiance: NRMSE ${c.nrmse_interior.toFixed(5)} <= ${kMaxNrmse} inside both silhouettes, ${c.nrmse.toFixed(5)} <= ${kMaxNrmseAll} over all`);
      await p.page.close();
    }
    const f = await open(a.name, new URLSearchParams({ mode: 'transfer', env: 'sunset.exr', camera, size: '640x480' }).toString());
    if (f.ready) {
      const ms = await f.page.evaluate(() => window.prtViewer.measure(30));
      frames.push({ asset: a.framesOnly ? path.basename(a.mesh) : a.name, vertices, triangles, ms, fps: 1000 / ms });
    }
    if (opt.images && f.ready) {
      const shot = await open(a.name, new URLSearchParams({ mode: 'transfer', env: 'sunset.exr', camera, size: '960x360', split: '1', rotate: 40 }).toString());
      const png = await shot.page.evaluate(() => window.prtViewer.png());
      fs.mkdirSync(opt.images, { recursive: true });
      fs.writeFileSync(path.join(opt.images, `viewer_${a.name}.png`), Buffer.from(png.split(',')[1], 'base64'));
      await shot.page.close();
    }
    await f.page.close();
    console.log(`     ${a.name}: ${vertices} vertices, ${triangles} triangles, ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  }

  if (!sweep) {
    // Area and punctual lights: two quad lights of different colours, a spot and a sun (punctual:
    // hard shadows) over a box on a ground (the geometry of
    // tests/tools/test_scene_area_lights.cpp), both objects baked per vertex: against prtview
    // --shade area (E per light x its radiance x albedo / pi, Gouraud), and the page's default
    // exposure is prtview's (1 / the 99th percentile of the baked lighting, 4 digits).
    {
    const d = path.join(out, 'area_scene');
    fs.mkdirSync(d);
    let g = '';
    for (let z = -3; z <= 3; ++z) for (let x = -3; x <= 3; ++x) g += `v ${x} 0 ${z}\n`;
    for (let j = 0; j < 6; ++j) for (let i = 0; i < 6; ++i) { const q = j * 7 + i + 1; g += `f ${q} ${q + 7} ${q + 8} ${q + 1}\n`; }
    fs.writeFileSync(path.join(d, 'ground.obj'), g);
    fs.writeFileSync(path.join(d, 'box.obj'), 'v -0.5 0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 1.5 -0.5\nv 0.5 1.5 -0.5\nv -0.5 0.5 0.5\n' +
      'v 0.5 0.5 0.5\nv -0.5 1.5 0.5\nv 0.5 1.5 0.5\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n');
    fs.writeFileSync(path.join(d, 'scene.json'), JSON.stringify({
      prtbake_scene: 1, bake: { products: ['ao'], samples: 1024, report: 0 },
      lights: [{ name: 'key', shape: 'quad', centre: [0.7, 4, 0.3], u: [2, 0, 0], v: [0, 0, 2], radiance: [10, 9, 7] },
               { name: 'fill', shape: 'quad', centre: [-3, 2, 0], u: [0, 0, 1.5], v: [0, 1.5, 0], radiance: [1, 2, 4] },
               // punctual lights (KHR_lights_punctual's kinds): stored as more columns, their
               // intensity in place of a radiance, so the page recolours them the same way
               { name: 'spot', shape: 'spot', position: [2.5, 3.5, 2], direction: [-0.55, -1, -0.45], inner_cone_angle: 12,
                 outer_cone_angle: 30, intensity: [9, 7, 5] },
               { name: 'sun', shape: 'directional', direction: [0.35, -1, 0.25], intensity: [0.3, 0.35, 0.45] }],
      objects: [{ mesh: 'ground.obj', role: 'both', material: { albedo: [0.6, 0.5, 0.4] } },
                { mesh: 'box.obj', role: 'both', material: { albedo: [0.8, 0.8, 0.8] } }] }));
    const h5 = path.join(d, 'area.prt.h5');
    run(opt.prtbake, ['scene', path.join(d, 'scene.json'), '-q', '-o', h5]);
    run(opt.prtbake, ['export', h5, '--to', 'web', '-o', path.join(out, 'area')]);
    const look = run(opt.prtview, [h5, '--shade', 'area', '--size', kSize, '-o', path.join(out, 'area', 'ref_area.png')]);
    const camera = look.match(/--camera (\S+)/)[1], exposure = Number(look.match(/exposure ([0-9.e+-]+) \(/)[1]);
    const p = await open('area', new URLSearchParams({ mode: 'area', camera, size: kSize }).toString());
    check(p.ready && !p.error, `area lights: the page draws (${p.error || 'no error'})`);
    if (p.ready) {
      const c = await p.page.evaluate((u) => window.prtViewer.compare(u), 'ref_area.png');
      const ours = await p.page.evaluate(() => window.prtViewer.exposure());
      rows.push({ asset: 'area lights', deg: '-', vertices: 57, triangles: 84, ...c });
      check(ours === exposure, `area lights: the page's default exposure ${ours} is prtview's ${exposure}`);
      const dflt = await open('area', '');  // an export without environments opens on what it can draw
      check(dflt.ready && !dflt.error, `area lights: the default view of an export without environments draws (${dflt.error || 'no error'})`);
      await dflt.page.close();
      check(c.nrmse_interior <= kMaxNrmse && c.nrmse <= kMaxNrmseAll,
            `area lights: NRMSE ${c.nrmse_interior.toFixed(5)} <= ${kMaxNrmse} inside both silhouettes, ${c.nrmse.toFixed(5)} <= ${kMaxNrmseAll} over all`);
    }
    await p.page.close();
    }

    // Glossy lobes, route B: the statue as a glossy scene object (Phong 24, order-11 shadowed
    // radiance under sunset.exr) against prtview --shade glossy, at its own exponent and at 128
    // (--phong: the lobe changes at run time).
    {
      const d = path.join(out, 'glossy_scene');
      fs.mkdirSync(d);
      fs.writeFileSync(path.join(d, 'scene.json'), JSON.stringify({
        prtbake_scene: 1, environment: sunset, bake: { integrator: 'qmc', samples: 64, report: 0 },
        objects: [{ mesh: path.join(opt.data, 'wuson.obj'), role: 'both', material: { albedo: [0.5, 0.5, 0.5], phong_exponent: 24, specular: [0.8, 0.7, 0.5] } }] }));
      const h5 = path.join(d, 'glossy.prt.h5');
      run(opt.prtbake, ['scene', path.join(d, 'scene.json'), '-q', '-o', h5]);
      run(opt.prtbake, ['export', h5, '--to', 'web', '-o', path.join(out, 'glossy')]);
      for (const phong of [null, 128]) {
        const ref = `ref_glossy_${phong || 'file'}.png`;
        const look = run(opt.prtview, [h5, '--shade', 'glossy', '--size', kSize, ...(phong ? ['--phong', String(phong)] : []),
                                       '-o', path.join(out, 'glossy', ref)]);
        const camera = look.match(/--camera (\S+)/)[1], exposure = Number(look.match(/exposure ([0-9.e+-]+) \(/)[1]);
        const q = new URLSearchParams({ mode: 'glossy', camera, exposure, size: kSize, ...(phong ? { phong } : {}) });
        const p = await open('glossy', q.toString());
        const c = p.ready ? await p.page.evaluate((u) => window.prtViewer.compare(u), ref) : { nrmse_interior: 1, nrmse: 1 };
        rows.push({ asset: `glossy statue, Phong ${phong || 24}`, deg: '-', vertices: 2117, triangles: 3732, ...c });
        check(p.ready && c.nrmse_interior <= kMaxNrmse && c.nrmse <= kMaxNrmseAll,
              `glossy lobes at Phong ${phong || 24}: NRMSE ${c.nrmse_interior.toFixed(5)} <= ${kMaxNrmse} inside both silhouettes, ` +
              `${c.nrmse.toFixed(5)} <= ${kMaxNrmseAll} over all (${p.error || 'drawn'})`);
        await p.page.close();
      }
    }

    // The comparison can fail: the bunny turned by 120 degrees against prtview's picture at 0.
    {
      const info = JSON.parse(fs.readFileSync(path.join(out, 'bunny', 'viewer.json'), 'utf8'));
      const look = fs.readFileSync(path.join(out, 'bunny_camera.txt'), 'utf8');
      const exposure = info.environments.find((e) => e.name === 'sunset.exr').exposure;
      const q = new URLSearchParams({ mode: 'transfer', env: 'sunset.exr', rotate: 120, exposure, camera: look, size: kSize });
      const p = await open('bunny', q.toString());
      const c = p.ready ? await p.page.evaluate((u) => window.prtViewer.compare(u), 'ref_0.png') : { nrmse_interior: 0 };
      check(c.nrmse_interior > 5 * kMaxNrmse, `the bunny turned 120 deg against prtview at 0 deg: NRMSE ${c.nrmse_interior.toFixed(4)} > ${5 * kMaxNrmse} (the check can fail)`);
      await p.page.close();
    }
    // Errors show in the page. A glb that is not one:
    fs.cpSync(path.join(out, 'bunny'), path.join(out, 'bad_glb'), { recursive: true });
    fs.writeFileSync(path.join(out, 'bad_glb', 'asset.glb'), 'this is not a glb');
    let p = await open('bad_glb', 'mode=transfer');
    check(!p.ready && /asset\.glb/.test(p.message), `a bad glb shows a message in the page: "${p.message.slice(0, 120)}"`);
    await p.page.close();
    // Opened as a file (double-clicked): browsers refuse its module scripts; the page says to serve it.
    {
      const page = await browser.newPage();
      await page.goto(`file://${path.join(out, 'bunny', 'index.html')}`);
      await page.waitForFunction('window.prtViewer && (window.prtViewer.ready || window.prtViewer.error)', { timeout: 60000 });
      const m = await page.evaluate(() => getComputedStyle(document.getElementById('message')).display !== 'none' ? document.getElementById('message').textContent : '');
      check(/http\.server/.test(m), `the folder opened as a file says to serve it: "${m.slice(0, 100)}"`);
      await page.close();
    }
    // A file without the product asked for (the statue has no band-1 radiance):
    p = await open('statue', 'mode=band1');
    check(!p.ready && /\/radiance\/band1/.test(p.message), `a file without the product shows a message in the page: "${p.message.slice(0, 120)}"`);
    await p.page.close();
    // The bunny's default page (band-1 radiance, the file's own environment) draws.
    p = await open('bunny', '');
    check(p.ready && !p.error, `the bunny's default view (band-1 radiance) draws (${p.error || 'no error'})`);
    await p.page.close();
  }
} catch (e) {
  failures.push(String(e.stack || e));
  console.log(`FAIL ${e.stack || e}`);
} finally {
  await browser.close();
  server.close();
}

console.log('\n| asset | vertices | triangles | rotation | NRMSE inside both silhouettes (px) | NRMSE, all covered px (px) | pixels off by > 2 of 255 |');
console.log('|---|---|---|---|---|---|---|');
for (const r of rows)
  console.log(`| ${r.asset} | ${r.vertices} | ${r.triangles} | ${typeof r.deg === 'number' ? r.deg + '°' : r.deg} | ${r.nrmse_interior.toFixed(5)} (${r.interior_pixels}) | ${r.nrmse.toFixed(5)} (${r.pixels}) | ${r.pixels_off_by_more_than_2} |`);
console.log('\n| asset | vertices | triangles | ms per frame (640x480) | frames per second |');
console.log('|---|---|---|---|---|');
for (const f of frames) console.log(`| ${f.asset} | ${f.vertices} | ${f.triangles} | ${f.ms.toFixed(1)} | ${f.fps.toFixed(1)} |`);
fs.writeFileSync(path.join(out, 'results.json'), JSON.stringify({ rows, frames, failures }, null, 1));
if (failures.length) {
  console.log(`\n${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('\nall checks passed');
