// viewer/viewer.js — the web viewer of a baked file (issue 34), shipped by
// `prtbake export FILE --to web -o DIR` with three.js (npm, copied at build time) beside it.
//
// What it draws: the glb that `prtbake export` writes (asset.glb: per vertex set a mesh whose
// _PRT_* attributes hold the baked rows, asset.extras.prtbake maps them, formats/SCHEMA.md
// "Exports"), shaded per vertex and interpolated (Gouraud, perspective-correct) exactly as prtview
// draws a per-vertex file, then tone mapped as prtview's PNGs are (view/image.h: 8-bit sRGB of
// exposure x value, clipped at 1). The shading math is not written here: the vertex shader is
// runtime/shaders/prt_lang.glsl, sh.inc and shade.inc — the GLSL mirror of prtshade that
// tests/shaders holds to the C++ core — compiled as GLSL ES 3.00 as they are (their comments and
// #include lines removed; the SSBOs prt_lang.glsl can declare are not: PRT_TRANSFER and PRT_LIGHT
// are defined first, a vertex's row from its attributes and a uniform array). Modes:
//   band1       E/pi = prt_shade_band1(n, R) / pi at the baked normal: exact under the environment
//               the file was baked with; it does not turn with the environment (the sky is in R).
//   transfer    prt_shade_transfer: sum_i T_i L_i, L = the chosen environment's SH at the file's
//               order, turned about +Y by the rotation (prtshade's sh::Rotation, precomputed per
//               degree at export: viewer.json), so the shadows follow the sky.
//   ao          AO x the unshadowed irradiance / pi of the environment (order 3).
//   unshadowed  the same surface without any visibility: sum_i (A_l y_i(n) / pi) L_i through the
//               same prt_shade_transfer (A_l: the clamped-cosine factors from viewer.json).
//   area        sum_l radiance_l E_l / pi, E_l the baked irradiance of area light l at unit
//               radiance (/area_lights/irradiance), radiance_l the file's times the page's colour
//               and intensity for that light (prtview --shade area, per vertex).
//   glossy      route B of glossy.inc: prt_shade_glossy_radiance of the vertex's /radiance/shadowed
//               row (read from a float texture by gl_VertexID) with the normalised Phong lobe about
//               the reflected view direction, times the object's specular colour (prtview --shade
//               glossy; objects without it black); the exponent changes at run time. The baked sky.
// Every mode but glossy is times the set's albedo (viewer.json: a scene object's, or the bounces'), as prtview.
// Per texel (a set with a lightmap, `prtbake texel`; the default where there is one, form=vertex
// for the per-vertex products): the same formulas per pixel in the fragment shader, the lightmap's
// values (the glb's float buffer views, RGBA32F textures of four channels each) sampled by
// SCHEMA's bilinear rule as prtview does (view/lightmap.h: (u W - 1/2, v H - 1/2), the four
// texels around it by texelFetch, clamped to the edge), band-1 and AO at the pixel's
// interpolated normal.
// URL parameters (the browser test uses them): mode, env (name or index), rotate (degrees),
// exposure, camera (prtview's form eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG]), size (WxH), split=1.
// window.prtViewer: ready, error, and the test's hooks (measure, compare, png).
// Any failure (a missing file, a bad glb, a file without the product asked for, a shader that does
// not compile) is shown as a message over the canvas, never as a blank canvas.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const state = { ready: false, error: null };
window.prtViewer = state;

function fail(text) {
  if (state.error) return;
  state.error = String(text);
  const m = $('message');
  m.textContent = 'prtbake viewer: ' + state.error;
  m.style.display = 'block';
}
window.addEventListener('error', (e) => fail(e.message));
window.addEventListener('unhandledrejection', (e) => fail(e.reason && e.reason.message ? e.reason.message : e.reason));

async function fetchOk(url, what) {
  let r;
  try {
    r = await fetch(url);
  } catch (e) {
    throw new Error(`cannot load ${url} (${what}): ${e.message}`);
  }
  if (!r.ok) throw new Error(`cannot load ${url} (${what}): HTTP ${r.status}`);
  return r;
}

// A shared shading body as GLSL ES source: comments and #include lines removed (WebGL has no
// #include; the page puts the bodies in order itself). What is left must be ASCII.
function shaderBody(name, text) {
  const body = text.replace(/\/\*[\s\S]*?\*\//g, '').replace(/\/\/.*$/gm, '').replace(/^[ \t]*#include.*$/gm, '');
  if (/[^\x00-\x7f]/.test(body)) throw new Error(`shaders/${name}: non-ASCII characters outside comments`);
  return body;
}

const MODES = {
  band1: { label: 'band-1 radiance (baked environment)', dataset: 'radiance/band1' },
  transfer: { label: 'diffuse transfer (any environment)', dataset: 'transfer/diffuse' },
  ao: { label: 'ambient occlusion x unshadowed', dataset: 'ao' },
  unshadowed: { label: 'unshadowed (no visibility)', dataset: null },
  area: { label: 'area lights (baked E per light)', dataset: 'area_lights/irradiance' },
  glossy: { label: 'glossy lobes (route B: radiance/shadowed)', dataset: 'radiance/shadowed' },
};

// The GLSL lines that copy a product's attributes into the float array `dst` (components in the
// row's order, SCHEMA.md "Exports": attribute k holds components 4k..4k+3).
function attributeCopy(product, dst) {
  const C = product.shape.reduce((a, b) => a * b, 1);
  const decl = [], copy = [];
  product.attributes.forEach((name, k) => {
    const n = Math.min(4, C - 4 * k);
    const id = name.toLowerCase();
    decl.push(`in ${n === 1 ? 'float' : 'vec' + n} ${id};`);
    for (let j = 0; j < n; ++j) copy.push(`${dst}[${4 * k + j}] = ${id}${n === 1 ? '' : '.' + 'xyzw'[j]};`);
  });
  return { decl: decl.join('\n'), copy: copy.join('\n  '), components: C };
}

const kRowWidth = 4096;  // the width of the shadowed-radiance texture (rows of all vertices, flat)
function vertexShader(mode, set, lib, order) {
  const p = (ds) => set.products.find((q) => q.dataset === ds);
  let decl = '', body = '';
  if (mode === 'none') {
    body = 'v_rgb = vec3(0.0);';
  } else if (mode === 'area') {
    const a = attributeCopy(p('area_lights/irradiance'), 'e');
    decl = `${a.decl}\nuniform vec3 prt_area[${a.components}];`;
    body = `float e[${a.components}];\n  ${a.copy}\n  v_rgb = vec3(0.0);\n  for (int l = 0; l < ${a.components}; ++l) v_rgb += prt_area[l] * e[l];\n  v_rgb /= PI;`;
  } else if (mode === 'glossy') {
    body = `float scales[PRT_SH_MAX_ORDER];
  prt_phong_band_scales(prt_phong, ${order}, scales);
  vec3 r = prt_glossy_reflection(normal, position, prt_eye);
  v_rgb = prt_shade_glossy_radiance(uint(gl_VertexID) * ${3 * order * order}u, ${order}, scales, r);`;
  } else if (mode === 'band1') {
    const a = attributeCopy(p('radiance/band1'), 'r');
    decl = a.decl;
    body = `float r[9];\n  ${a.copy}\n  v_rgb = prt_shade_band1(normal, r) / PI;`;
  } else if (mode === 'transfer') {
    const a = attributeCopy(p('transfer/diffuse'), 'prt_t');
    decl = a.decl;
    body = `${a.copy}\n  v_rgb = prt_shade_transfer(0u, ${order});`;
  } else {
    const ao = mode === 'ao';
    decl = ao ? 'in float _ao;' : '';
    body = `float y[PRT_SH_MAX_COEFFS];
  prt_sh_eval(${order}, normalize(normal), y);
  for (int i = 0; i < ${order * order}; ++i) prt_t[i] = y[i] * prt_cosine[i] / PI;
  v_rgb = ${ao ? '_ao * ' : ''}prt_shade_transfer(0u, ${order});`;
  }
  return `precision highp float;
precision highp int;
#define PRT_SH_MAX_ORDER ${Math.max(order, 3)}
#define PI 3.14159265358979323846
uniform mat4 modelViewMatrix;
uniform mat4 projectionMatrix;
uniform float prt_light[${3 * order * order}];
uniform float prt_cosine[${order * order}];
uniform vec3 prt_albedo;
uniform highp sampler2D prt_s;
uniform float prt_phong;
uniform vec3 prt_eye;
in vec3 position;
in vec3 normal;
${decl}
out vec3 v_rgb;
float prt_t[PRT_SH_MAX_ORDER * PRT_SH_MAX_ORDER];
#define PRT_TRANSFER(i) prt_t[(i)]
#define PRT_LIGHT(i) prt_light[(i)]
#define PRT_SHADOWED(i) texelFetch(prt_s, ivec2(int(i) % ${kRowWidth}, int(i) / ${kRowWidth}), 0).r
#define PRT_VISIBILITY(i) 0.0
#define PRT_GLOSSY_MATRIX(i) 0.0
${lib}
void main() {
  ${body}
  v_rgb *= prt_albedo;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}
`;
}

// prtview's tone map (view/image.h): v = clamp(exposure x, 0, 1), then the sRGB transfer function.
const toneMap = `uniform float exposure;
out vec4 out_colour;
float srgb(float x) {
  float v = clamp(exposure * x, 0.0, 1.0);
  return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}
void show(vec3 rgb) { out_colour = vec4(srgb(rgb.r), srgb(rgb.g), srgb(rgb.b), 1.0); }
`;
const fragmentShader = `precision highp float;
in vec3 v_rgb;
${toneMap}
void main() { show(v_rgb); }
`;

// Per texel: a pass-through vertex shader and the shading in the fragment shader.
const texelVertexShader = `precision highp float;
uniform mat4 modelViewMatrix;
uniform mat4 projectionMatrix;
in vec3 position;
in vec3 normal;
in vec2 uv1;
out vec2 v_uv;
out vec3 v_normal;
void main() {
  v_uv = uv1;
  v_normal = normal;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}
`;
function texelFragmentShader(mode, maps, channels, lib, order) {
  const samplers = Array.from({ length: maps }, (_, j) => `uniform highp sampler2D prt_map${j};`).join('\n');
  const fill = (dst) => Array.from({ length: maps }, (_, j) => {
    const n = Math.min(4, channels - 4 * j);
    return `  s = bilinear(prt_map${j});\n` + Array.from({ length: n }, (_, k) => `  ${dst}[${4 * j + k}] = s.${'xyzw'[k]};`).join('\n');
  }).join('\n');
  let body;
  if (mode === 'band1') body = `float r[9];\n${fill('r')}\n  rgb = prt_shade_band1(normalize(v_normal), r) / PI;`;
  else if (mode === 'transfer') body = `${fill('prt_t')}\n  rgb = prt_shade_transfer(0u, ${order});`;
  else body = `float a[1];\n${fill('a')}
  float y[PRT_SH_MAX_COEFFS];
  prt_sh_eval(${order}, normalize(v_normal), y);
  for (int i = 0; i < ${order * order}; ++i) prt_t[i] = y[i] * prt_cosine[i] / PI;
  rgb = a[0] * prt_shade_transfer(0u, ${order});`;
  return `precision highp float;
precision highp int;
#define PRT_SH_MAX_ORDER ${Math.max(order, 3)}
#define PI 3.14159265358979323846
uniform float prt_light[${3 * order * order}];
uniform float prt_cosine[${order * order}];
uniform vec3 prt_albedo;
uniform ivec2 prt_map_size;
${samplers}
in vec2 v_uv;
in vec3 v_normal;
float prt_t[PRT_SH_MAX_ORDER * PRT_SH_MAX_ORDER];
#define PRT_TRANSFER(i) prt_t[(i)]
#define PRT_LIGHT(i) prt_light[(i)]
#define PRT_SHADOWED(i) 0.0
#define PRT_VISIBILITY(i) 0.0
#define PRT_GLOSSY_MATRIX(i) 0.0
${lib}
${toneMap}
vec4 texel(highp sampler2D m, ivec2 p) { return texelFetch(m, clamp(p, ivec2(0), prt_map_size - 1), 0); }
vec4 bilinear(highp sampler2D m) {
  vec2 st = v_uv * vec2(prt_map_size) - 0.5, c = floor(st), f = st - c;
  ivec2 p = ivec2(c);
  return mix(mix(texel(m, p), texel(m, p + ivec2(1, 0)), f.x), mix(texel(m, p + ivec2(0, 1)), texel(m, p + ivec2(1, 1)), f.x), f.y);
}
void main() {
  vec4 s;
  vec3 rgb;
${body}
  show(rgb * prt_albedo);
}
`;
}

function parseCamera(spec) {
  const cam = { up: [0, 1, 0], fov: 45 };
  for (const part of spec.split(':')) {
    const [key, value] = part.split('=');
    const nums = value ? value.split(',').map(Number) : [];
    if (key === 'fov') cam.fov = nums[0];
    else if ((key === 'eye' || key === 'at' || key === 'up') && nums.length === 3 && nums.every(Number.isFinite)) cam[key] = nums;
    else throw new Error(`camera '${spec}': cannot read '${part}' (eye=X,Y,Z:at=X,Y,Z[:up=X,Y,Z][:fov=DEG])`);
  }
  if (!cam.eye || !cam.at) throw new Error(`camera '${spec}': needs eye and at`);
  return cam;
}

async function main() {
  const [info, langText, shText, shadeText, glossyText] = await Promise.all([
    fetchOk('viewer.json', 'the export\'s description').then((r) => r.json()),
    ...['prt_lang.glsl', 'sh.inc', 'shade.inc', 'glossy.inc'].map((f) => fetchOk('shaders/' + f, 'a shader body').then((r) => r.text())),
  ]);
  const lib = [shaderBody('prt_lang.glsl', langText), shaderBody('sh.inc', shText), shaderBody('shade.inc', shadeText),
               shaderBody('glossy.inc', glossyText)].join('\n');
  $('meta').textContent = JSON.stringify(info.file, null, 1);

  const glbBytes = await (await fetchOk(info.glb, 'the baked mesh')).arrayBuffer();
  let gltf;
  try {
    gltf = await new GLTFLoader().parseAsync(glbBytes, './');
  } catch (e) {
    throw new Error(`${info.glb} is not a glb prtbake export wrote: ${e.message || e}`);
  }
  const extras = gltf.asset && gltf.asset.extras && gltf.asset.extras.prtbake;
  if (!extras || !Array.isArray(extras.sets)) throw new Error(`${info.glb} has no asset.extras.prtbake: not written by prtbake export`);
  for (const set of extras.sets) set.products = set.products || [];  // an empty list is written as null

  // The meshes with their vertex set's products.
  const drawn = [];
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    const a = gltf.parser.associations.get(o);
    const set = a && extras.sets.find((s) => s.mesh === a.meshes);
    if (set && o.geometry.getAttribute('normal')) drawn.push({ mesh: o, set });
  });
  if (drawn.length === 0) throw new Error(`${info.glb} holds no triangle mesh with normals to shade`);
  // A set's lightmap dataset of a mode's product ({dataset, shape, bufferView}), if any.
  const texelData = (set, mode) => {
    const ds = MODES[mode].dataset;
    if (!ds || mode === 'area' || mode === 'glossy' || !set.lightmap || !Array.isArray(set.lightmap.datasets)) return null;
    return set.lightmap.datasets.find((d) => d.dataset === 'lightmap/' + ds || d.dataset.endsWith('/lightmap/' + ds)) || null;
  };
  const hasVertex = (set, mode) => !MODES[mode].dataset || set.products.some((p) => p.dataset === MODES[mode].dataset);
  const has = (set, mode) => hasVertex(set, mode) || texelData(set, mode) !== null;
  // The lightmap's float images as RGBA32F textures of four channels each (loaded once per dataset).
  const textures = new Map();
  async function lightmapTextures(d) {
    if (textures.has(d.bufferView)) return textures.get(d.bufferView);
    if (d.dtype !== 'float32') throw new Error(`${info.glb}: ${d.dataset} is ${d.dtype}, the viewer reads float32 lightmaps`);
    const [H, W] = d.shape, C = d.shape.slice(2).reduce((a, b) => a * b, 1);
    const view = await gltf.parser.getDependency('bufferView', d.bufferView);
    const values = new Float32Array(view.slice(0));
    if (values.length !== H * W * C) throw new Error(`${info.glb}: ${d.dataset} holds ${values.length} floats, not ${H}x${W}x${C}`);
    const maps = [];
    for (let j = 0; 4 * j < C; ++j) {
      const data = new Float32Array(H * W * 4);
      for (let t = 0; t < H * W; ++t) for (let k = 0; k < 4 && 4 * j + k < C; ++k) data[4 * t + k] = values[t * C + 4 * j + k];
      const tex = new THREE.DataTexture(data, W, H, THREE.RGBAFormat, THREE.FloatType);
      tex.minFilter = tex.magFilter = THREE.NearestFilter;
      tex.generateMipmaps = false;
      tex.needsUpdate = true;
      maps.push(tex);
    }
    const out = { maps, size: new THREE.Vector2(W, H), channels: C };
    textures.set(d.bufferView, out);
    return out;
  }
  for (const d of drawn) for (const m of Object.keys(MODES)) { const t = texelData(d.set, m); if (t) await lightmapTextures(t); }
  const anyTexel = drawn.some((d) => Object.keys(MODES).some((m) => texelData(d.set, m)));
  const envNeeded = (m) => m !== 'band1' && m !== 'area' && m !== 'glossy';
  // The modes the export can draw: some set has the product, and an environment when it needs one.
  const available = Object.keys(MODES).filter((m) => drawn.some((d) => has(d.set, m)) && (!envNeeded(m) || info.environments.length));

  const requested = params.get('mode');
  let mode = requested || available.find((m) => m !== 'unshadowed') || null;
  if (requested && !MODES[requested]) throw new Error(`unknown mode '${requested}' (band1, transfer, ao, unshadowed, area, glossy)`);
  if (!mode) {
    const lacking = ['transfer', 'ao'].find((m) => drawn.some((d) => has(d.set, m)));
    throw new Error(lacking ? `${info.source}: its /${MODES[lacking].dataset} needs an environment and the export has none (prtbake export ... --to web --env ENV.exr)`
                            : `${info.source}: the file holds none of /radiance/band1, /transfer/diffuse, /ao, /area_lights/irradiance, /radiance/shadowed: nothing to shade`);
  }
  if (!drawn.some((d) => has(d.set, mode)))
    throw new Error(`${info.source}: the file has no /${MODES[mode].dataset} (its products: ${[...new Set(drawn.flatMap((d) => d.set.products.map((p) => p.dataset)))].join(', ') || 'none'})`);
  if (envNeeded(mode) && info.environments.length === 0)
    throw new Error(`${info.source}: '${mode}' needs an environment and the export has none (prtbake export ... --to web --env ENV.exr)`);

  // Sizes, camera, renderer.
  const size = (params.get('size') || '640x480').split('x').map(Number);
  if (size.length !== 2 || !size.every((v) => Number.isInteger(v) && v > 0 && v <= 8192)) throw new Error(`size '${params.get('size')}': expects WxH`);
  const canvas = $('canvas');
  canvas.width = size[0];
  canvas.height = size[1];
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: false, preserveDrawingBuffer: true, powerPreference: 'high-performance' });
  renderer.setPixelRatio(1);
  renderer.setSize(size[0], size[1], false);
  renderer.setClearColor(0x000000, 1);
  renderer.autoClear = false;
  renderer.debug.onShaderError = (gl, program, vs, fs) => {
    fail('a shader did not compile: ' + (gl.getShaderInfoLog(vs) || '') + (gl.getShaderInfoLog(fs) || '') + (gl.getProgramInfoLog(program) || ''));
  };

  const scene = new THREE.Scene();
  scene.add(gltf.scene);
  gltf.scene.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(gltf.scene);
  const centre = box.getCenter(new THREE.Vector3()), radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
  let cam;
  if (params.get('camera')) cam = parseCamera(params.get('camera'));
  else {
    const d = radius / Math.sin((22.5 * Math.PI) / 180) * 1.05, dir = new THREE.Vector3(0.35, 0.5, 1).normalize();
    cam = { eye: centre.clone().addScaledVector(dir, d).toArray(), at: centre.toArray(), up: [0, 1, 0], fov: 45 };
  }
  const camera = new THREE.PerspectiveCamera(cam.fov, size[0] / size[1], 1, 2);
  const target = new THREE.Vector3(...cam.at);
  camera.position.set(...cam.eye);
  camera.up.set(...cam.up);
  const placeCamera = () => {
    camera.lookAt(target);
    const dist = camera.position.distanceTo(target);
    camera.near = Math.max(1e-3 * dist, dist - centre.distanceTo(target) - 2 * radius);  // depth precision
    camera.far = dist + centre.distanceTo(target) + 2 * radius;
    camera.updateProjectionMatrix();
  };
  placeCamera();

  // Environments: [rotation degree][3 * order^2] channel-major, from viewer.json.
  const envIndex = (() => {
    const e = params.get('env');
    if (e === null) return Math.max(0, info.environments.findIndex((x) => x.baked));
    const i = info.environments.findIndex((x, k) => x.name === e || String(k) === e);
    if (i < 0) throw new Error(`environment '${e}' is not in the export (${info.environments.map((x) => x.name).join(', ')})`);
    return i;
  })();
  const ui = {
    mode,
    env: envIndex,
    rotate: Number(params.get('rotate') || 0),
    exposure: params.get('exposure') ? Number(params.get('exposure')) : null,
    split: params.get('split') === '1',
    texel: params.get('form') !== 'vertex',
    phong: params.get('phong') ? Number(params.get('phong')) : null,
  };
  if (!Number.isFinite(ui.rotate)) throw new Error(`rotate '${params.get('rotate')}': expects degrees`);
  if (ui.exposure !== null && !(ui.exposure > 0)) throw new Error(`exposure '${params.get('exposure')}': expects a number > 0`);

  // Area lights: the file's (viewer.json) with the page's colour and intensity per light; a set's
  // columns of /area_lights/irradiance name its lights (the product's "lights", one per line).
  const lights = (info.lights || []).map((l) => ({ ...l, colour: [1, 1, 1], intensity: 1 }));
  const lightColumns = (set) => {
    const names = (set.products.find((q) => q.dataset === 'area_lights/irradiance').lights || '').split('\n');
    return names.map((n) => {
      const l = lights.find((x) => x.name === n);
      if (!l) throw new Error(`${info.glb}: set ${set.name} names the light '${n}', which the file does not hold`);
      return l;
    });
  };
  const lightRadiance = (l) => [0, 1, 2].map((c) => l.radiance[c] * l.colour[c] * l.intensity);
  const albedoOf = (k) => {
    const meta = info.file.vertex_sets[extras.sets.indexOf(drawn[k].set)];
    return meta && meta.albedo ? meta.albedo : [1, 1, 1];
  };
  // prtview's exposure of area lights: 1 / the 99th percentile of the baked per-vertex luminance.
  const areaExposure = (() => {
    const lum = [];
    drawn.forEach((d, k) => {
      if (!has(d.set, 'area')) return;
      const cols = lightColumns(d.set), product = d.set.products.find((q) => q.dataset === 'area_lights/irradiance');
      const attrs = product.attributes.map((a) => d.mesh.geometry.getAttribute(a.toLowerCase()));
      const alb = albedoOf(k), n = d.mesh.geometry.getAttribute('position').count;
      for (let v = 0; v < n; ++v) {
        const rgb = [0, 0, 0];
        cols.forEach((l, j) => {
          const a = attrs[j >> 2], e = a.array[v * a.itemSize + (j & 3)];
          for (let c = 0; c < 3; ++c) rgb[c] += l.radiance[c] * e;
        });
        lum.push((0.2126 * rgb[0] * alb[0] + 0.7152 * rgb[1] * alb[1] + 0.0722 * rgb[2] * alb[2]) / Math.PI);
      }
    });
    lum.sort((a, b) => a - b);
    const p99 = lum.length ? lum[Math.min(lum.length - 1, Math.floor(0.99 * lum.length))] : 0;
    return p99 > 0 ? Number((1 / p99).toPrecision(4)) : 1;
  })();

  // Glossy objects: the lobe's exponent and specular colour (viewer.json), and a set's
  // /radiance/shadowed rows as one R32F texture, kRowWidth floats a row (vertex v's row at
  // v * 3 order^2), read by the vertex shader's PRT_SHADOWED.
  const metaOf = (k) => info.file.vertex_sets[extras.sets.indexOf(drawn[k].set)] || {};
  const phongOf = (k) => metaOf(k).phong_exponent || 0;
  const specularOf = (k) => metaOf(k).specular || [1, 1, 1];
  const blank = new THREE.DataTexture(new Float32Array(1), 1, 1, THREE.RedFormat, THREE.FloatType);
  blank.needsUpdate = true;
  function shadowedTexture(k, order) {
    const d = drawn[k], product = d.set.products.find((q) => q.dataset === 'radiance/shadowed');
    const C = 3 * order * order, V = d.mesh.geometry.getAttribute('position').count;
    const rows = Math.ceil((V * C) / kRowWidth), data = new Float32Array(rows * kRowWidth);
    product.attributes.forEach((name, j) => {
      const a = d.mesh.geometry.getAttribute(name.toLowerCase());
      for (let v = 0; v < V; ++v) for (let c = 0; c < a.itemSize; ++c) data[v * C + 4 * j + c] = a.array[v * a.itemSize + c];
    });
    const tex = new THREE.DataTexture(data, kRowWidth, rows, THREE.RedFormat, THREE.FloatType);
    tex.minFilter = tex.magFilter = THREE.NearestFilter;
    tex.needsUpdate = true;
    return tex;
  }

  const materials = new Map();  // key: mode|set index
  function material(m, k) {
    const set = drawn[k].set;
    const td = texelData(set, m);
    if (td && (ui.texel || !hasVertex(set, m))) return texelMaterial(m, k, td);
    const key = m + '|' + k;
    if (!materials.has(key)) {
      const transfer = set.products.find((p) => p.dataset === 'transfer/diffuse');
      // transfer and unshadowed: the file's order (unshadowed: 3 without transfer); AO: 3.
      const shadowed = set.products.find((p) => p.dataset === 'radiance/shadowed');
      const order = m === 'glossy' ? shadowed.sh_order : m === 'band1' || m === 'area' || m === 'none' ? 1 : m === 'ao' || !transfer ? 3 : transfer.sh_order;
      const mat = new THREE.RawShaderMaterial({
        glslVersion: THREE.GLSL3,
        vertexShader: vertexShader(m, set, lib, order),
        fragmentShader,
        side: THREE.DoubleSide,
        uniforms: {
          prt_light: { value: new Float32Array(3 * order * order) },
          prt_cosine: { value: new Float32Array(order * order) },
          prt_albedo: { value: new THREE.Vector3(...albedoOf(k)) },
          prt_area: { value: [] },
          prt_s: { value: m === 'glossy' ? shadowedTexture(k, order) : blank },
          prt_phong: { value: 0 },
          prt_eye: { value: new THREE.Vector3() },
          exposure: { value: 1 },
        },
      });
      if (m === 'glossy') mat.uniforms.prt_albedo.value.set(...specularOf(k));
      mat.userData.phong = m === 'glossy' ? phongOf(k) : 0;
      mat.userData.mesh = drawn[k].mesh;
      mat.userData.order = order;
      mat.userData.columns = m === 'area' ? lightColumns(set) : [];
      mat.uniforms.prt_area.value = mat.userData.columns.map(() => new THREE.Vector3());
      materials.set(key, mat);
    }
    return materials.get(key);
  }
  function texelMaterial(m, k, td) {
    const key = 'texel|' + m + '|' + k;
    if (!materials.has(key)) {
      const set = drawn[k].set, tex = textures.get(td.bufferView);
      const transfer = m === 'transfer' ? td.shape[2] : 0;
      const order = m === 'band1' ? 1 : m === 'transfer' ? Math.round(Math.sqrt(transfer)) : 3;
      const uniforms = {
        prt_light: { value: new Float32Array(3 * order * order) },
        prt_cosine: { value: new Float32Array(order * order) },
        prt_albedo: { value: new THREE.Vector3(...albedoOf(k)) },
        prt_map_size: { value: tex.size },
        exposure: { value: 1 },
      };
      tex.maps.forEach((t, j) => { uniforms['prt_map' + j] = { value: t }; });
      const mat = new THREE.RawShaderMaterial({
        glslVersion: THREE.GLSL3,
        vertexShader: texelVertexShader,
        fragmentShader: texelFragmentShader(m, tex.maps.length, tex.channels, lib, order),
        side: THREE.DoubleSide,
        uniforms,
      });
      mat.userData.order = order;
      mat.userData.columns = [];
      materials.set(key, mat);
      if (!drawn[k].mesh.geometry.getAttribute('uv1')) throw new Error(`${info.glb}: set ${set.name} has a lightmap but no TEXCOORD_1`);
    }
    return materials.get(key);
  }
  function updateUniforms(mat) {
    const order = mat.userData.order, n = order * order;
    const env = info.environments[ui.env];
    if (env) {
      const deg = ((Math.round(ui.rotate) % 360) + 360) % 360, N = env.order * env.order;
      const row = env.sh_by_degree[deg];
      const light = mat.uniforms.prt_light.value;
      for (let c = 0; c < 3; ++c) for (let i = 0; i < n; ++i) light[c * n + i] = row[c * N + i];
    }
    for (let l = 0; l < order; ++l) for (let m = -l; m <= l; ++m) mat.uniforms.prt_cosine.value[l * (l + 1) + m] = info.clamped_cosine[l];
    if (mat.uniforms.prt_phong) {
      mat.uniforms.prt_phong.value = ui.phong ?? mat.userData.phong;
      mat.userData.mesh.updateMatrixWorld(true);
      mat.uniforms.prt_eye.value.copy(camera.position).applyMatrix4(mat.userData.mesh.matrixWorld.clone().invert());
    }
    if (mat.uniforms.prt_area) mat.userData.columns.forEach((l, j) => mat.uniforms.prt_area.value[j].set(...lightRadiance(l)));
    mat.uniforms.exposure.value = exposure();
  }
  const exposure = () => ui.exposure ?? (ui.mode === 'area' ? areaExposure : info.environments[ui.env] ? info.environments[ui.env].exposure : 1);

  function drawWith(m) {
    drawn.forEach((d, k) => {
      const mm = has(d.set, m) ? m : m !== 'glossy' && info.environments.length ? 'unshadowed' : 'none';
      d.mesh.material = material(mm, k);
      updateUniforms(d.mesh.material);
    });
    renderer.render(scene, camera);
  }
  function render() {
    renderer.setScissorTest(false);
    renderer.setViewport(0, 0, size[0], size[1]);
    renderer.clear();
    if (!ui.split) {
      camera.aspect = size[0] / size[1];
      camera.updateProjectionMatrix();
      drawWith(ui.mode);
    } else {
      const half = Math.floor(size[0] / 2);
      camera.aspect = half / size[1];
      camera.updateProjectionMatrix();
      renderer.setScissorTest(true);
      for (const [x, m] of [[0, ui.mode], [half, 'unshadowed']]) {
        renderer.setViewport(x, 0, half, size[1]);
        renderer.setScissor(x, 0, half, size[1]);
        drawWith(m);
      }
      renderer.setScissorTest(false);
    }
    const cr = $('cap-right');
    $('cap-left').style.display = cr.style.display = ui.split ? 'block' : 'none';
    cr.style.left = Math.floor(size[0] / 2) + 4 + 'px';
    $('cap-left').textContent = MODES[ui.mode].label;
    $('rotate-value').textContent = `${((Math.round(ui.rotate) % 360) + 360) % 360}°` + (ui.mode === 'band1' ? ' (band-1 radiance holds the baked sky: it does not turn)' : '');
    $('exposure-value').textContent = exposure().toPrecision(4);
    const missing = drawn.filter((d) => !has(d.set, ui.mode)).map((d) => d.set.name);
    $('status').textContent = missing.length ? `${missing.length} vertex set(s) without ${MODES[ui.mode].dataset}, drawn ${info.environments.length ? 'unshadowed' : 'black'}: ${missing.slice(0, 4).join(', ')}` : '';
  }
  let pending = false;
  const redraw = () => {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => {
      pending = false;
      if (!state.error) render();
    });
  };

  // Controls.
  for (const m of available) $('mode').add(new Option(MODES[m].label, m, false, m === ui.mode));
  info.environments.forEach((e, k) => $('env').add(new Option(e.name + (e.baked ? ' (baked with)' : ''), String(k), false, k === ui.env)));
  $('mode').onchange = (e) => { ui.mode = e.target.value; redraw(); };
  $('env').onchange = (e) => { ui.env = Number(e.target.value); if ($('exposure').value === '0') ui.exposure = null; redraw(); };
  $('rotate').value = String(ui.rotate);
  $('rotate').oninput = (e) => { ui.rotate = Number(e.target.value); redraw(); };
  $('exposure').oninput = (e) => {
    const base = info.environments[ui.env] ? info.environments[ui.env].exposure : 1;
    ui.exposure = base * Math.pow(2, Number(e.target.value));
    redraw();
  };
  for (const l of lights) {
    const row = document.createElement('label');
    row.textContent = `light ${l.name} `;
    const colour = Object.assign(document.createElement('input'), { type: 'color', value: '#ffffff' });
    const gain = Object.assign(document.createElement('input'), { type: 'range', min: -4, max: 4, step: 0.1, value: 0 });
    colour.oninput = () => { l.colour = [1, 3, 5].map((i) => parseInt(colour.value.slice(i, i + 2), 16) / 255); redraw(); };
    gain.oninput = () => { l.intensity = Math.pow(2, Number(gain.value)); redraw(); };
    row.append(colour, gain);
    $('lights').append(row);
  }
  $('phong-row').style.display = available.includes('glossy') ? 'block' : 'none';
  $('phong').oninput = (e) => { ui.phong = Math.pow(2, Number(e.target.value)); $('phong-value').textContent = ui.phong.toPrecision(3); redraw(); };
  $('texel').checked = ui.texel;
  $('texel-row').style.display = anyTexel ? 'block' : 'none';
  $('texel').onchange = (e) => { ui.texel = e.target.checked; redraw(); };
  if (!info.environments.length)  // nothing to turn, no unshadowed surface to set beside
    for (const id of ['env', 'rotate', 'split']) $(id).closest('label').style.display = 'none';
  $('split').checked = ui.split;
  $('split').onchange = (e) => { ui.split = e.target.checked; redraw(); };
  let drag = null;
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  canvas.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY, orbit: e.shiftKey || e.button === 2 }; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointerup', () => { drag = null; });
  canvas.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX;
    drag.y = e.clientY;
    if (!drag.orbit) {
      ui.rotate = (((ui.rotate + dx * 0.5) % 360) + 360) % 360;
      $('rotate').value = String(Math.round(ui.rotate));
    } else {
      const offset = camera.position.clone().sub(target);
      const s = new THREE.Spherical().setFromVector3(offset);
      s.theta -= dx * 0.01;
      s.phi = Math.min(Math.PI - 1e-3, Math.max(1e-3, s.phi - dy * 0.01));
      camera.position.copy(target).add(new THREE.Vector3().setFromSpherical(s));
      camera.up.set(0, 1, 0);
      placeCamera();
    }
    redraw();
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    camera.position.sub(target).multiplyScalar(Math.exp(e.deltaY * 1e-3)).add(target);
    placeCamera();
    redraw();
  }, { passive: false });

  render();
  if (state.error) return;

  // The browser test's hooks.
  const gl = renderer.getContext();
  const sync = () => gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
  // Mean milliseconds per frame over `frames` frames, the environment turning one degree a frame
  // (each frame waited for: readPixels of one pixel).
  state.measure = (frames) => {
    render();
    sync();
    const start = ui.rotate, t0 = performance.now();
    for (let i = 0; i < frames; ++i) {
      ui.rotate = start + i + 1;
      render();
      sync();
    }
    const ms = (performance.now() - t0) / frames;
    ui.rotate = start;
    render();
    return ms;
  };
  state.png = () => canvas.toDataURL('image/png');
  state.exposure = () => exposure();
  // NRMSE of this picture against a reference image (prtview's PNG of the same view), both in
  // 8-bit sRGB scaled to [0, 1]: RMSE over the pixels either picture covers (not black) and the
  // three channels, over the reference's range there (max - min) — view/image.h's definition;
  // nrmse_interior the same over the pixels inside both silhouettes (the pixel and its 8
  // neighbours covered in both), where the two rasterisers cannot disagree about coverage.
  state.compare = async (url) => {
    render();
    const blob = await (await fetchOk(url, 'the reference picture')).blob();
    const bitmap = await createImageBitmap(blob, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    if (bitmap.width !== size[0] || bitmap.height !== size[1]) throw new Error(`${url} is ${bitmap.width}x${bitmap.height}, the view ${size[0]}x${size[1]}`);
    const c2 = document.createElement('canvas');
    c2.width = size[0];
    c2.height = size[1];
    const ctx = c2.getContext('2d', { willReadFrequently: true });
    ctx.drawImage(bitmap, 0, 0);
    const ref = ctx.getImageData(0, 0, size[0], size[1]).data;
    const ours = new Uint8Array(size[0] * size[1] * 4);
    gl.readPixels(0, 0, size[0], size[1], gl.RGBA, gl.UNSIGNED_BYTE, ours);
    const W = size[0], H = size[1];
    const refAt = (x, y) => 4 * (y * W + x), oursAt = (x, y) => 4 * ((H - 1 - y) * W + x);  // readPixels: bottom row first
    const lit = (a, i) => (a[i] | a[i + 1] | a[i + 2]) !== 0;
    // A pixel inside the silhouettes of both pictures: it and its 8 neighbours covered in both.
    const inside = (x, y) => {
      for (let v = y - 1; v <= y + 1; ++v)
        for (let u = x - 1; u <= x + 1; ++u)
          if (u < 0 || v < 0 || u >= W || v >= H || !lit(ref, refAt(u, v)) || !lit(ours, oursAt(u, v))) return false;
      return true;
    };
    const all = { sum: 0, count: 0 }, interior = { sum: 0, count: 0 };
    let lo = 255, hi = 0, worst = 0, off2 = 0;
    for (let y = 0; y < H; ++y)
      for (let x = 0; x < W; ++x) {
        const r = refAt(x, y), o = oursAt(x, y);
        if (!lit(ref, r) && !lit(ours, o)) continue;
        let px = 0, sq = 0;
        for (let c = 0; c < 3; ++c) {
          const d = ours[o + c] - ref[r + c];
          sq += d * d;
          px = Math.max(px, Math.abs(d));
          lo = Math.min(lo, ref[r + c]);
          hi = Math.max(hi, ref[r + c]);
        }
        all.sum += sq;
        ++all.count;
        if (inside(x, y)) {
          interior.sum += sq;
          ++interior.count;
        }
        worst = Math.max(worst, px);
        if (px > 2) ++off2;
      }
    const range = hi > lo ? (hi - lo) / 255 : 1;
    const rmse = (a) => Math.sqrt(a.sum / Math.max(1, 3 * a.count)) / 255;
    return { nrmse: rmse(all) / range, nrmse_interior: rmse(interior) / range, rmse: rmse(all), pixels: all.count,
             interior_pixels: interior.count, max_abs: worst, pixels_off_by_more_than_2: off2 };
  };
  state.ready = true;
}

main().catch((e) => fail(e && e.message ? e.message : e));
