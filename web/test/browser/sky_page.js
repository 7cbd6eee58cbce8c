// The page of the browser test of NeuralSky (three.js): it draws the sky into
// a float render target through the exported GLSL ES network and compares
// every pixel with the JavaScript forward pass of the same weights file, on
// the view direction that pixel's fragment computed (drawn by a second pass).
import { BufferAttribute, BufferGeometry, DataTexture, FloatType, Mesh, MeshLambertMaterial, OrthographicCamera, PlaneGeometry, ShaderMaterial, PerspectiveCamera, RGBAFormat, Scene, Vector3, WebGLRenderer, WebGLRenderTarget } from 'three';
import { NeuralSky as Network } from '../../src/neural_sky.js';
import { shEval } from '../../src/sky_sh.js';
import { NeuralSky, skybakeLighting } from '../../src/three.js';
import { networks, prtGlsl } from './fixture.js';

function run({ name, weights, glsl }) {
  const W = 48, H = 32;
  const canvas = document.createElement('canvas');
  document.body.appendChild(canvas);
  const renderer = new WebGLRenderer({ canvas, antialias: false });
  renderer.setSize(W, H, false);
  const target = new WebGLRenderTarget(W, H, { type: FloatType, format: RGBAFormat });
  const scene = new Scene();
  const sky = new NeuralSky(weights, glsl);
  sky.scale.setScalar(1000);
  sky.setSun(20, 30);
  scene.add(sky);
  const camera = new PerspectiveCamera(90, W / H, 0.1, 2000);
  camera.position.set(0, 0, 0);
  camera.lookAt(new Vector3(0.3, 0.2, 1)); // the horizon across the middle
  camera.updateMatrixWorld();
  renderer.setRenderTarget(target);
  renderer.render(scene, camera);
  const px = new Float32Array(W * H * 4);
  renderer.readRenderTargetPixels(target, 0, 0, W, H, px);
  renderer.setRenderTarget(null);
  renderer.render(scene, camera);

  // The view direction each fragment of the sky box sees, against the pixel
  // centre's ray in JavaScript.
  const dirBox = new Mesh(sky.geometry, new ShaderMaterial({
    vertexShader: sky.material.vertexShader, side: sky.material.side, depthWrite: false,
    fragmentShader: 'varying vec3 vWorldPosition; void main() { gl_FragColor = vec4(normalize(vWorldPosition - cameraPosition), 1.0); }',
  }));
  dirBox.scale.copy(sky.scale);
  const dirScene = new Scene();
  dirScene.add(dirBox);
  renderer.setRenderTarget(target);
  renderer.render(dirScene, camera);
  const dpx = new Float32Array(W * H * 4);
  renderer.readRenderTargetPixels(target, 0, 0, W, H, dpx);
  renderer.setRenderTarget(null);
  let dirMaxErr = 0;
  for (let j = 0; j < H; ++j)
    for (let i = 0; i < W; ++i) {
      const d = new Vector3(((i + 0.5) / W) * 2 - 1, ((j + 0.5) / H) * 2 - 1, 0.5).unproject(camera).sub(camera.position).normalize();
      const k = 4 * (j * W + i);
      dirMaxErr = Math.max(dirMaxErr, Math.hypot(dpx[k] - d.x, dpx[k + 1] - d.y, dpx[k + 2] - d.z));
    }
  // The network on the directions the fragments saw (the rasterizer's
  // interpolation is not the network's business).
  const net = new Network(weights);
  const sun = sky.material.uniforms.sunPosition.value.clone().normalize();
  const clamp = (v) => Math.max(-1, Math.min(1, v));
  let maxRel = 0, compared = 0, peak = 0, worst = null;
  const rows = [];
  for (let j = 0; j < H; ++j)
    for (let i = 0; i < W; ++i) {
      const k = 4 * (j * W + i);
      const d = new Vector3(dpx[k], dpx[k + 1], dpx[k + 2]).normalize();
      const L = net.radiance(clamp(d.y), clamp(d.dot(sun)), clamp(sun.y), 1);
      rows.push([L, [px[4 * (j * W + i)], px[4 * (j * W + i) + 1], px[4 * (j * W + i) + 2]], [i, j, d.y, d.dot(sun)]]);
      peak = Math.max(peak, L[0], L[1], L[2]);
    }
  for (const [L, G, at] of rows)
    for (let c = 0; c < 3; ++c) {
      if (L[c] < 1e-3 * peak) continue;
      const rel = Math.abs(G[c] - L[c]) / L[c];
      if (rel > maxRel) worst = { L, G, at, c };
      maxRel = Math.max(maxRel, rel);
      ++compared;
    }
  // The GPU's own exp2 and log, against JavaScript's: the floor of any
  // agreement of a network whose activations and decoding use them.
  const N = 256;
  const probe = new WebGLRenderTarget(N, 1, { type: FloatType, format: RGBAFormat });
  const quad = new Mesh(new PlaneGeometry(2, 2), new ShaderMaterial({
    vertexShader: 'varying vec2 vUv; void main() { vUv = uv; gl_Position = vec4(position.xy, 0.0, 1.0); }',
    fragmentShader: 'varying vec2 vUv; void main() { float x = -12.0 + 24.0 * vUv.x; gl_FragColor = vec4(exp2(x), log(exp2(x)), x, 1.0); }',
  }));
  const probeScene = new Scene();
  probeScene.add(quad);
  renderer.setRenderTarget(probe);
  renderer.render(probeScene, new OrthographicCamera(-1, 1, 1, -1, 0, 1));
  const q = new Float32Array(N * 4);
  renderer.readRenderTargetPixels(probe, 0, 0, N, 1, q);
  renderer.setRenderTarget(null);
  let exp2MaxRel = 0, logMaxAbs = 0;
  for (let i = 0; i < N; ++i) {
    const x = q[4 * i + 2];
    exp2MaxRel = Math.max(exp2MaxRel, Math.abs(q[4 * i] / Math.pow(2, x) - 1));
    logMaxAbs = Math.max(logMaxAbs, Math.abs(q[4 * i + 1] - Math.log(q[4 * i])));
  }
  renderer.dispose();
  canvas.remove();
  return { name, maxRel, compared, peak, worst, exp2MaxRel, logMaxAbs, dirMaxErr, webgl2: renderer.capabilities.isWebGL2 !== false };
}

// skybakeLighting on one triangle whose vertices carry the same baked data,
// so that its middle pixel is that data lit: 'prt' against the dot product
// of the transfer and the light, 'ao' against the irradiance of the SH light
// integrated over the hemisphere of the normal (not the shader's closed form).
function lighting({ weights, glsl }) {
  const sky = new NeuralSky(weights, glsl, { order: 3 });
  sky.setSun(25, -40);
  const light = sky.shLight();
  const W = 16, H = 16;
  const renderer = new WebGLRenderer({ antialias: false });
  renderer.setSize(W, H, false);
  const target = new WebGLRenderTarget(W, H, { type: FloatType, format: RGBAFormat });
  const camera = new OrthographicCamera(-1, 1, 1, -1, 0.1, 10);
  camera.position.set(0, 0, 5);
  const albedo = [0.8, 0.6, 0.4];
  const normal = [0.3, 0.8, 0.52];
  const nl = Math.hypot(...normal);
  const n = normal.map((v) => v / nl);
  const out = {};
  for (const mode of ['prt', 'ao', 'ao-texture']) {
    const g = new BufferGeometry();
    g.setAttribute('position', new BufferAttribute(new Float32Array([-3, -3, 0, 3, -3, 0, 0, 3, 0]), 3));
    g.setAttribute('normal', new BufferAttribute(new Float32Array([...n, ...n, ...n]), 3));
    const t = Array.from({ length: 16 }, (_, i) => Math.fround(Math.sin(1.7 * i + 0.3) * 0.5));
    for (let a = 0; a < 4; ++a)
      g.setAttribute(`_prt_${a}`, new BufferAttribute(new Float32Array([0, 1, 2].flatMap(() => t.slice(4 * a, 4 * a + 4))), 4));
    g.setAttribute('_ao', new BufferAttribute(new Float32Array([0.625, 0.625, 0.625]), 1));
    const material = new MeshLambertMaterial({ color: 0x000000 });
    if (mode === 'ao-texture') {
      // The AO in a texture (glTF's occlusionTexture, three's aoMap) instead of an attribute.
      g.setAttribute('uv', new BufferAttribute(new Float32Array([0.5, 0.5, 0.5, 0.5, 0.5, 0.5]), 2));
      material.aoMap = new DataTexture(new Float32Array([0.625, 0, 0, 1]), 1, 1, RGBAFormat, FloatType);
      material.aoMap.needsUpdate = true;
    }
    const options = mode === 'prt' ? { mode, prtGlsl, attributes: 4, order: 3, albedo }
      : { mode: 'ao', order: 3, albedo, aoAttribute: mode === 'ao' ? '_ao' : 'aoMap' };
    const hook = skybakeLighting(material, options);
    hook.update(light);
    const scene = new Scene();
    scene.add(new Mesh(g, material));
    renderer.setRenderTarget(target);
    renderer.render(scene, camera);
    const px = new Float32Array(4);
    renderer.readRenderTargetPixels(target, W / 2, H / 2, 1, 1, px);
    renderer.setRenderTarget(null);
    let want;
    if (mode === 'prt') {
      want = albedo.map((k, c) => k * light.coefficients.reduce((s, L, i) => s + L[c] * t[i], 0));
    } else {
      // E = ∫ L(ω) max(0, n·ω) dω over a 400 × 800 grid, L the order-2 part of the light.
      const E = [0, 0, 0];
      const y = new Float64Array(9);
      const NT = 400, NP = 800;
      for (let a = 0; a < NT; ++a) {
        const th = ((a + 0.5) * Math.PI) / NT;
        for (let b = 0; b < NP; ++b) {
          const ph = ((b + 0.5) * 2 * Math.PI) / NP;
          const w = [Math.sin(th) * Math.cos(ph), Math.sin(th) * Math.sin(ph), Math.cos(th)];
          const c = w[0] * n[0] + w[1] * n[1] + w[2] * n[2];
          if (c <= 0) continue;
          shEval(2, w[0], w[1], w[2], y);
          const dw = Math.sin(th) * (Math.PI / NT) * ((2 * Math.PI) / NP) * c;
          for (let k = 0; k < 3; ++k) for (let i = 0; i < 9; ++i) E[k] += light.coefficients[i][k] * y[i] * dw;
        }
      }
      want = albedo.map((k, c) => (k / Math.PI) * E[c] * 0.625);
    }
    out[mode] = { got: [px[0], px[1], px[2]], want, rel: Math.max(...want.map((v, c) => Math.abs(px[c] - v) / Math.abs(v))) };
  }
  renderer.dispose();
  return out;
}

try {
  window.skybakeLighting = lighting(networks[0]);
  window.skybakeResult = networks.map(run);
} catch (e) {
  console.error(String(e && e.stack ? e.stack : e));
  window.skybakeResult = { error: String(e) };
}
