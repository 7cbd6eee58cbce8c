// The page of `skybake web`: a baked model lit by the neural sky in WebGL 2.
// `skybake web` writes data.js beside it, which sets window.SKYBAKE_SITE:
//   { model: base64 .glb, weights: the weights JSON, skyGlsl: `sky export
//     --format glsl-es`, prt: null | { glsl, attributes, order, channels } }
// (scripts, not fetched files, so that the page opens from file:// too).
// Everything else is bundled into one script by esbuild at build time.
import {
  Box3,
  CustomToneMapping,
  BufferAttribute,
  Color,
  DirectionalLight,
  DoubleSide,
  Mesh,
  MeshBasicMaterial,
  MeshLambertMaterial,
  PlaneGeometry,
  PCFSoftShadowMap,
  PerspectiveCamera,
  Scene,
  ShaderChunk,
  SRGBColorSpace,
  Vector3,
  WebGLRenderer,
} from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { NeuralSky, skybakeLighting } from '../src/three.js';

const say = (text, isError = false) => {
  const el = document.getElementById('message');
  el.textContent = text;
  el.className = isError ? 'error' : '';
  (isError ? console.error : console.log)(`skybake: ${text}`);
};

function base64ToBuffer(b64) {
  const bin = atob(b64);
  const out = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) out[i] = bin.charCodeAt(i);
  return out.buffer;
}

function parseGlb(buffer) {
  return new Promise((resolve, reject) => new GLTFLoader().parse(buffer, '', resolve, (e) => reject(new Error(`the model: ${e.message ?? e}`))));
}

// The sun's transmittance from the model's ground to space along elevation
// e (degrees), from the weights file's atmosphere (its components' extinction
// and density profiles), by the midpoint rule; zero below the horizon.
function sunTransmittance(atm, elevationDeg) {
  const R0 = atm.planet_radius_km, Rt = atm.top_radius_km;
  const mu = Math.sin((elevationDeg * Math.PI) / 180);
  if (mu < 0) return [0, 0, 0];
  const length = -R0 * mu + Math.sqrt(R0 * R0 * (mu * mu - 1) + Rt * Rt);
  const density = (c, h) => {
    const p = c.profile ?? {};
    if (p.type === 'exponential') return Math.exp(-h / p.scale_height_km);
    if (p.type === 'tent') return Math.max(0, 1 - Math.abs(h - p.center_km) / p.half_width_km);
    return 1;
  };
  const tau = [0, 0, 0], n = 256, dt = length / n;
  for (let i = 0; i < n; ++i) {
    const t = (i + 0.5) * dt;
    const h = Math.sqrt(R0 * R0 + t * t + 2 * R0 * t * mu) - R0;
    for (const c of atm.components) for (let k = 0; k < 3; ++k) tau[k] += c.extinction_per_km[k] * density(c, h) * dt;
  }
  return tau.map((x) => Math.exp(-x));
}

// skybake's tone curve (src/core/tone_curve.h: Narkowicz's ACES fit at
// linear × 2^EV), so that the page looks as `skybake view` does; three.js
// then applies the sRGB encoding, as skybake does.
ShaderChunk.tonemapping_pars_fragment = ShaderChunk.tonemapping_pars_fragment.replace(
  'vec3 CustomToneMapping( vec3 color ) { return color; }',
  `vec3 CustomToneMapping( vec3 color ) {
    vec3 x = color * toneMappingExposure;
    return clamp( ( x * ( 2.51 * x + 0.03 ) ) / ( x * ( 2.43 * x + 0.59 ) + 0.14 ), 0.0, 1.0 );
  }`,
);

// The camera of `skybake view` and the previews (preview_camera() in
// src/bake/preview.cpp): looking at the bounds' centre from azimuth and
// elevation (degrees; azimuth from +z towards +x), at the distance that fits
// the bounds' sphere in the field of view.
function previewCamera(camera, box, azimuthDeg, elevationDeg, fovYDeg, aspect) {
  const centre = box.getCenter(new Vector3());
  const radius = Math.max(0.5 * box.getSize(new Vector3()).length(), 1e-20);
  const az = (azimuthDeg * Math.PI) / 180, el = (elevationDeg * Math.PI) / 180;
  const toEye = new Vector3(Math.cos(el) * Math.sin(az), Math.sin(el), Math.cos(el) * Math.cos(az));
  const half = (0.5 * fovYDeg * Math.PI) / 180;
  const fit = Math.min(Math.sin(half), Math.sin(Math.atan(Math.tan(half) * aspect)));
  camera.fov = fovYDeg;
  camera.aspect = aspect;
  camera.position.copy(centre).addScaledVector(toEye, (radius / fit) * 1.02);
  camera.up.set(0, 1, 0);
  if (Math.abs(toEye.y) > 0.999) camera.up.set(0, 0, -1);
  camera.lookAt(centre);
  camera.updateProjectionMatrix();
  return centre;
}

async function main() {
  const data = window.SKYBAKE_SITE;
  if (!data) throw new Error('data.js is missing or did not load (write the site again with `skybake web`)');
  const canvas = document.getElementById('view');
  if (!canvas.getContext('webgl2')) throw new Error('this browser has no WebGL 2');
  // URL settings: elevation, azimuth, exposure (EV) as in the panel; view=AZ,EL,
  // fov, shading, phong and specular as `skybake view --set KEY=VALUE`;
  // ground=off (the viewer draws none) and aa=off (one sample per pixel,
  // `--set samples=1`).
  const params = new URLSearchParams(window.location.search);
  const number = (key, fallback, lo, hi) => {
    if (!params.has(key)) return fallback;
    const x = Number(params.get(key));
    if (!Number.isFinite(x) || x < lo || x > hi) throw new Error(`?${key}=${params.get(key)} is not a number in [${lo}, ${hi}]`);
    return x;
  };
  // The default view is the viewer's azimuth, lower (5° above the model, not 30°) to show the sky.
  const viewParam = (params.get('view') ?? '35,5').split(',').map(Number);
  if (viewParam.length !== 2 || !viewParam.every(Number.isFinite)) throw new Error(`?view=${params.get('view')} is not AZIMUTH,ELEVATION in degrees`);
  const fov = number('fov', 35, 2, 160);
  // The glossy layer, as `skybake view --set phong=… --set specular=…`.
  const phong = number('phong', 32, 0.5, 100000);
  const specular = number('specular', 0.25, 0, 100);

  const renderer = new WebGLRenderer({ canvas, antialias: params.get('aa') !== 'off', preserveDrawingBuffer: true });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
  renderer.toneMapping = CustomToneMapping;
  renderer.outputColorSpace = SRGBColorSpace;
  renderer.shadowMap.enabled = true;
  renderer.shadowMap.type = PCFSoftShadowMap; // 3×3 bilinear PCF taps, as the viewer filters
  const scene = new Scene();
  scene.background = new Color(0, 0, 0);

  const sky = new NeuralSky(data.weights, data.skyGlsl, { order: data.prt ? data.prt.order : 3 });
  sky.scale.setScalar(1e5);
  scene.add(sky);

  const gltf = await parseGlb(base64ToBuffer(data.model));
  const model = gltf.scene;
  const box = new Box3().setFromObject(model, true); // precise: the vertices in world space, as skybake bounds the mesh
  const size = box.getSize(new Vector3()).length() || 1;
  const radius = 0.5 * size;
  const centre = box.getCenter(new Vector3());

  // The sky's light through the bake: the transfer where the file has one
  // ('PRT'), its AO (_AO, else COLOR_0) times the unshadowed SH light ('AO'),
  // or none ('sun': the sun alone). Each mesh gets a material per mode the
  // file allows; the panel switches between them. Lambert, as the bake
  // assumes; the albedo is a PRT bake's _ALBEDO where the file has it (what
  // `skybake view` draws), else the material's colour and image.
  const hooks = [];
  const modes = new Set(['sun']);
  let aoWithoutUv = false;
  const meshes = [];
  model.traverse((o) => {
    if (!o.isMesh) return;
    o.castShadow = true;
    o.receiveShadow = true;
    const a = o.geometry.attributes;
    const perVertex = a._albedo && a._albedo.itemSize === 3;
    const base = perVertex ? new Color(1, 1, 1) : o.material && o.material.color ? o.material.color : new Color(0.8, 0.8, 0.8);
    const albedo = perVertex ? '_albedo' : base.toArray();
    const side = o.material?.side;
    // Both faces cast shadows, as in the viewer's depth pass (three's default is the back faces).
    const make = (extra = {}) => new MeshLambertMaterial({ color: base.clone(), map: o.material?.map ?? null, side, shadowSide: DoubleSide, ...extra });
    // 'flat': one constant colour, the benchmarks' baseline (as the viewer's FLAT pass); not in the panel.
    const materials = { sun: make(), flat: new MeshBasicMaterial({ color: 0x808080 }) };
    if (perVertex) skybakeLighting(materials.sun, { mode: 'none', albedo }); // the albedo, no sky light
    if (data.prt && a._prt_0) {
      materials.PRT = make();
      hooks.push(skybakeLighting(materials.PRT, { mode: 'prt', prtGlsl: data.prt.glsl, attributes: data.prt.attributes, order: data.prt.order, albedo }));
      modes.add('PRT');
      if (a._shading) {
        // DPRT: the glossy layer through the shading coefficient A (_SHADING).
        materials['PRT + glossy'] = make();
        hooks.push(skybakeLighting(materials['PRT + glossy'], {
          mode: 'prt', prtGlsl: data.prt.glsl, attributes: data.prt.attributes, order: data.prt.order, albedo,
          glossy: { attribute: '_shading', exponent: phong, specular },
        }));
        modes.add('PRT + glossy');
      }
    }
    const aoMap = o.material?.aoMap ?? null; // glTF's occlusionTexture (`skybake ao --texture`)
    const aoUv = aoMap && aoMap.channel ? `uv${aoMap.channel}` : 'uv';
    if (a._ao || a.color) {
      materials.AO = make();
      hooks.push(skybakeLighting(materials.AO, { mode: 'ao', aoAttribute: a._ao ? '_ao' : 'color', order: 3, albedo }));
      modes.add('AO');
    } else if (aoMap && a[aoUv]) {
      materials.AO = make({ aoMap });
      hooks.push(skybakeLighting(materials.AO, { mode: 'ao', aoAttribute: 'aoMap', order: 3, albedo }));
      modes.add('AO');
    } else if (aoMap) {
      aoWithoutUv = true;
    }
    meshes.push({ mesh: o, materials });
  });
  // ?shading= as `skybake view --set shading=`: prt, dprt, ao or sun.
  const asked = { prt: 'PRT', dprt: 'PRT + glossy', ao: 'AO', sun: 'sun' }[params.get('shading') ?? ''];
  if (params.has('shading') && !asked) throw new Error(`?shading=${params.get('shading')} is not prt, dprt, ao or sun`);
  if (asked && !modes.has(asked)) throw new Error(`?shading=${params.get('shading')}: this model has no data for it`);
  const shading = asked ?? (modes.has('PRT') ? 'PRT' : modes.has('AO') ? 'AO' : 'sun');
  let currentShading = null;
  const setShading = (mode) => {
    currentShading = mode;
    for (const { mesh, materials } of meshes) mesh.material = materials[mode] ?? materials.sun;
  };
  setShading(shading);
  if (shading === 'sun')
    say(aoWithoutUv
      ? 'this model has an occlusion texture but no UVs to read it with, and no baked transfer (_PRT_i) or AO attribute (_AO, COLOR_0): shown with the sun only'
      : 'this model has no baked transfer (_PRT_i) and no AO (_AO, COLOR_0 or an occlusion texture): shown with the sun only', true);
  scene.add(model);

  // The ground around the model, at the atmosphere's ground albedo, lit by
  // the sun and by the sky (AO 1), so that the view below the horizon is land.
  const groundAlbedo = data.weights.atmosphere?.ground_albedo ?? [0.1, 0.1, 0.1];
  const groundGeometry = new PlaneGeometry(size * 200, size * 200).rotateX(-Math.PI / 2);
  groundGeometry.setAttribute('_ao', new BufferAttribute(new Float32Array(groundGeometry.attributes.position.count).fill(1), 1));
  const groundMaterial = new MeshLambertMaterial({ color: new Color(...groundAlbedo) });
  hooks.push(skybakeLighting(groundMaterial, { mode: 'ao', aoAttribute: '_ao', order: 3, albedo: groundAlbedo }));
  const ground = new Mesh(groundGeometry, groundMaterial);
  ground.position.set(centre.x, box.min.y - 1e-3 * size, centre.z);
  ground.receiveShadow = true;
  if (params.get('ground') !== 'off') scene.add(ground); // `skybake view` draws no ground

  // The sun's shadow map as `skybake view` makes it: 2048², an orthographic
  // frustum around the bounds' sphere, looked up 1.5 texels along the normal
  // and filtered by 3×3 bilinear comparisons (three's PCFSoftShadowMap).
  const sun = new DirectionalLight(0xffffff, 1);
  sun.castShadow = true;
  sun.shadow.mapSize.set(2048, 2048);
  Object.assign(sun.shadow.camera, { left: -radius, right: radius, top: radius, bottom: -radius, near: 0.5 * radius, far: 3.5 * radius });
  sun.shadow.normalBias = (1.5 * 2 * radius) / 2048;
  sun.shadow.bias = -1e-4;
  sun.target.position.copy(centre);
  scene.add(sun, sun.target);

  const camera = new PerspectiveCamera();
  const resetCamera = () => previewCamera(camera, box, viewParam[0], viewParam[1], fov, canvas.clientWidth / Math.max(1, canvas.clientHeight));
  resetCamera();
  const controls = new OrbitControls(camera, canvas);
  controls.target.copy(centre);
  controls.update();
  // The depth range of the viewer (the bounds' sphere, ±1.5 radii around the
  // centre's distance); with the ground, from near the eye to its far edge.
  const groundShown = params.get('ground') !== 'off';
  const fitDepthRange = () => {
    const dist = camera.position.distanceTo(centre);
    const near = groundShown ? 0.01 * dist : Math.max(dist - 1.5 * radius, 1e-3 * dist);
    const far = dist + (groundShown ? 200 * size : 1.5 * radius);
    if (camera.near !== near || camera.far !== far) {
      camera.near = near;
      camera.far = far;
      camera.updateProjectionMatrix();
    }
  };
  fitDepthRange();

  // Controls.
  const ui = (id) => document.getElementById(id);
  const state = { elevation: 25, azimuth: 135, exposure: 0, auto: true, animate: false };
  state.elevation = number('elevation', state.elevation, -20, 90);
  state.azimuth = number('azimuth', state.azimuth, -360, 360);
  state.exposure = number('exposure', state.exposure, -64, 64);
  if (params.has('exposure')) state.auto = false;
  ui('elevation').value = state.elevation;
  ui('azimuth').value = state.azimuth;
  ui('exposure').value = state.exposure;
  ui('auto').checked = state.auto;
  ui('elevation').oninput = (e) => (state.elevation = Number(e.target.value));
  ui('azimuth').oninput = (e) => (state.azimuth = Number(e.target.value));
  ui('exposure').oninput = (e) => ((state.exposure = Number(e.target.value)), (state.auto = false), (ui('auto').checked = false));
  ui('auto').onchange = (e) => (state.auto = e.target.checked);
  ui('animate').onchange = (e) => (state.animate = e.target.checked);
  ui('screenshot').onclick = () => {
    const a = document.createElement('a');
    a.href = canvas.toDataURL('image/png');
    a.download = 'skybake.png';
    a.click();
  };
  for (const mode of ['PRT', 'PRT + glossy', 'AO', 'sun'].filter((m) => modes.has(m))) ui('shading').add(new Option(mode, mode, mode === shading, mode === shading));
  ui('shading').onchange = (e) => setShading(e.target.value);
  // Shift-drag on the view moves the sun (the orbit camera takes plain drags).
  let drag = null;
  canvas.addEventListener('pointerdown', (e) => {
    if (!e.shiftKey) return;
    controls.enabled = false;
    drag = { x: e.clientX, y: e.clientY, elevation: state.elevation, azimuth: state.azimuth };
  });
  window.addEventListener('pointermove', (e) => {
    if (!drag) return;
    state.azimuth = (((drag.azimuth + (e.clientX - drag.x) * 0.5) % 360) + 360) % 360;
    state.elevation = Math.max(-20, Math.min(90, drag.elevation - (e.clientY - drag.y) * 0.25));
    ui('elevation').value = state.elevation;
    ui('azimuth').value = state.azimuth;
  });
  window.addEventListener('pointerup', () => {
    drag = null;
    controls.enabled = true;
  });

  const resize = () => {
    const w = canvas.clientWidth, h = canvas.clientHeight;
    if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) || canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
      renderer.setSize(w, h, false);
      camera.aspect = w / h;
      camera.updateProjectionMatrix();
    }
  };

  let last = performance.now();
  let lightKey = '';
  const frame = (now) => {
    const dt = (now - last) / 1000;
    last = now;
    if (state.animate) {
      state.elevation = ((state.elevation + 100 + dt * 4) % 200) - 100; // −100° to 100°, a day in 50 s
      ui('elevation').value = Math.max(-20, Math.min(90, state.elevation));
    }
    const elevation = Math.max(-20, Math.min(90, state.elevation));
    sky.setSun(elevation, state.azimuth);
    sun.castShadow = currentShading !== 'flat'; // the flat baseline draws the model alone
    const s = sky.material.uniforms.sunPosition.value;
    sun.position.copy(centre).addScaledVector(s, 2 * radius);
    const key = `${elevation.toFixed(2)} ${state.azimuth.toFixed(2)}`;
    if (key !== lightKey) {
      lightKey = key;
      const light = sky.shLight();
      for (const h of hooks) h.update(light);
      // three's Lambert is albedo/π × the light's irradiance, as the bake's
      // radiance is: the sun gives irradiance T per unit sun irradiance.
      const T = sunTransmittance(data.weights.atmosphere, elevation);
      sun.color.setRGB(T[0], T[1], T[2]);
      sun.intensity = 1;
      const up = Math.max(0, Math.sin((elevation * Math.PI) / 180)) * (0.2126 * T[0] + 0.7152 * T[1] + 0.0722 * T[2]);
      // Automatic exposure: the sky's mean radiance (L00 / 2√π) to mid-grey.
      const L00 = light.coefficients[0];
      // A white surface facing up sees πL̄ from the sky and `up` from the sun.
      const mean = (0.2126 * L00[0] + 0.7152 * L00[1] + 0.0722 * L00[2]) / (2 * Math.sqrt(Math.PI)) + up / Math.PI;
      state.autoExposure = mean > 0 ? Math.log2(0.18 / mean) : 0;
    }
    const ev = state.auto ? state.autoExposure : state.exposure;
    renderer.toneMappingExposure = Math.pow(2, ev);
    ui('ev').textContent = `${ev >= 0 ? '+' : ''}${ev.toFixed(2)} EV`;
    resize();
    controls.update();
    fitDepthRange();
    renderer.render(scene, camera);
    window.skybakeSiteFrames = (window.skybakeSiteFrames ?? 0) + 1;
    requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
  // For tests and scripts: the mean RGB (0–255) of a rectangle of the view,
  // in fractions of its size from the top left, drawn and read at once.
  const regionMean = (x0, y0, x1, y1) => {
    fitDepthRange();
    renderer.render(scene, camera);
    const gl = renderer.getContext();
    const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight;
    const X = Math.floor(x0 * W), w = Math.max(1, Math.floor((x1 - x0) * W)), h = Math.max(1, Math.floor((y1 - y0) * H));
    const Y = H - Math.floor(y0 * H) - h;
    const px = new Uint8Array(w * h * 4);
    gl.readPixels(X, Y, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const m = [0, 0, 0];
    for (let i = 0; i < px.length; i += 4) for (let k = 0; k < 3; ++k) m[k] += px[i + k];
    return m.map((v) => v / (w * h));
  };
  // The whole view, RGBA 8-bit, top row first.
  const pixels = () => {
    fitDepthRange();
    renderer.render(scene, camera);
    const gl = renderer.getContext();
    const W = gl.drawingBufferWidth, H = gl.drawingBufferHeight;
    const px = new Uint8Array(W * H * 4);
    gl.readPixels(0, 0, W, H, gl.RGBA, gl.UNSIGNED_BYTE, px);
    const out = new Uint8Array(px.length);
    for (let y = 0; y < H; ++y) out.set(px.subarray((H - 1 - y) * W * 4, (H - y) * W * 4), y * W * 4);
    return Array.from(out);
  };
  // setShading(mode): 'PRT', 'PRT + glossy', 'AO', 'sun' or 'flat'.
  window.skybakeSite = { shading, regionMean, pixels, setShading };
}

main().catch((e) => {
  say(e.message ?? String(e), true);
  window.skybakeSite = { error: e.message ?? String(e) };
});
