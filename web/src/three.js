// skybake-web/three: skybake's neural sky and baked sky light in three.js.
//
//   NeuralSky      a drop-in for three.js's Sky (examples/jsm/objects/Sky.js):
//                  a box around the camera, drawn at the far plane, whose
//                  fragments run the network of `skybake sky train`. Set the
//                  sun as with Sky: material.uniforms.sunPosition (or setSun()).
//   skybakeLighting an onBeforeCompile hook for a mesh's material that adds the
//                  sky's SH light through the baked transfer (_PRT_i) or the
//                  baked AO (_AO, COLOR_0) times the unshadowed SH light.
//
// The shader code is not written here: the network's GLSL is the output of
// `skybake sky export W.json --format glsl-es`, the transfer's dot product that
// of `skybake prt export BAKED.glb --format glsl-es`, the generators that
// write every other language. The weights file itself drives the per-frame
// SH projection in JavaScript (SkyProjector).
import { BackSide, BoxGeometry, DataTexture, DataUtils, HalfFloatType, LinearFilter, Mesh, RGBAFormat, ClampToEdgeWrapping, RepeatWrapping, ShaderMaterial, Vector3 } from 'three';
import { NeuralSky as Network } from './neural_sky.js';
import { SkyProjector, gaussLegendreUnit, horizonRule, shEval } from './sky_sh.js';

const VERTEX = /* glsl */ `
varying vec3 vWorldPosition;
void main() {
  vec4 worldPosition = modelMatrix * vec4(position, 1.0);
  vWorldPosition = worldPosition.xyz;
  gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
  gl_Position.z = gl_Position.w; // on the far plane
}
`;

// skybake_sky() comes first (the exported function), then this. A network of
// an aerosol family takes its amount as a fifth argument.
const fragment = (family) => /* glsl */ `
varying vec3 vWorldPosition;
uniform vec3 sunPosition;
uniform vec3 up;
uniform float density;
uniform float aerosol;
uniform float sunIrradiance;
void main() {
  vec3 v = normalize(vWorldPosition - cameraPosition);
  vec3 s = normalize(sunPosition);
  vec3 u = normalize(up);
  vec3 L = skybake_sky(clamp(dot(v, u), -1.0, 1.0), clamp(dot(v, s), -1.0, 1.0), clamp(dot(s, u), -1.0, 1.0), density${family ? ', aerosol' : ''});
  gl_FragColor = vec4(max(L, vec3(0.0)) * sunIrradiance, 1.0);
  #include <tonemapping_fragment>
  #include <colorspace_fragment>
}
`;

function checkGlsl(glsl, name) {
  if (typeof glsl !== 'string' || !new RegExp(`\\b${name}\\s*\\(`).test(glsl))
    throw new Error(`skybake: the shader text has no ${name}() (write it with \`skybake sky export W.json --format glsl-es\`)`);
}

export class NeuralSky extends Mesh {
  // weights: the weights file of `skybake sky train` (text, object or a
  // skybake-web NeuralSky); glsl: `skybake sky export` of the same file with
  // --format glsl-es. options.order: the SH order of shLight() (default 3).
  constructor(weights, glsl, { order = 3 } = {}) {
    checkGlsl(glsl, 'skybake_sky');
    const network = weights instanceof Network ? weights : new Network(weights);
    const material = new ShaderMaterial({
      name: 'SkybakeNeuralSky',
      uniforms: {
        sunPosition: { value: new Vector3(0, 1, 0) },
        up: { value: new Vector3(0, 1, 0) },
        density: { value: 1 },
        aerosol: { value: 1 },
        sunIrradiance: { value: 1 },
      },
      vertexShader: VERTEX,
      fragmentShader: glsl + fragment(network.family !== null),
      side: BackSide,
      depthWrite: false,
    });
    super(new BoxGeometry(1, 1, 1), material);
    this.isSky = true;
    this.type = 'NeuralSky';
    this.network = network;
    this.projector = new SkyProjector(order, horizonRule());
  }

  // A network of an aerosol family: its amount, a multiple of its
  // atmosphere's, for the sky and for shLight().
  setAerosol(amount) {
    this.network.aerosol = amount; // checks the range
    this.material.uniforms.aerosol.value = amount;
    return this;
  }

  // The sun at elevation and azimuth (degrees; azimuth from +z towards +x,
  // the glTF frame of skybake's SH).
  setSun(elevationDeg, azimuthDeg) {
    const e = (elevationDeg * Math.PI) / 180, a = (azimuthDeg * Math.PI) / 180;
    this.material.uniforms.sunPosition.value.set(Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a));
    return this;
  }

  // The sun's elevation and azimuth (degrees) from sunPosition.
  sunAngles() {
    const s = this.material.uniforms.sunPosition.value.clone().normalize();
    return {
      elevation: (Math.asin(Math.max(-1, Math.min(1, s.y))) * 180) / Math.PI,
      azimuth: (Math.atan2(s.x, s.z) * 180) / Math.PI,
    };
  }

  // The sky's light in SH for the current sun (skybake's convention, glTF
  // frame), scaled by sunIrradiance: { order, coefficients: [[r, g, b], ...] }.
  shLight() {
    const { elevation, azimuth } = this.sunAngles();
    const u = this.material.uniforms;
    const light = this.projector.project(this.network, elevation, azimuth, u.density.value);
    const k = u.sunIrradiance.value;
    light.coefficients = light.coefficients.map((c) => [c[0] * k, c[1] * k, c[2] * k]);
    return light;
  }
}

// k̂_l = 2π ∫_0^1 t^a P_l(t) dt, the zonal factors of the Phong lobe max(t, 0)^a
// (phong_lobe_zonal() in src/sphere/sh.cpp, which uses Γ functions; here
// Gauss–Legendre with 64 nodes on [0, 1]).
export function phongLobeZonal(l, a) {
  const { nodes, weights } = gaussLegendreUnit(64);
  let sum = 0;
  for (let k = 0; k < nodes.length; ++k) {
    const t = nodes[k];
    let p0 = 1, p1 = t; // Legendre's recurrence
    let p = l === 0 ? 1 : t;
    for (let n = 2; n <= l; ++n) {
      p = ((2 * n - 1) * t * p1 - (n - 1) * p0) / n;
      p0 = p1;
      p1 = p;
    }
    sum += weights[k] * Math.pow(t, a) * p;
  }
  return 2 * Math.PI * sum;
}

// The DPRT glossy layer of an SH light as `skybake view` draws it: texel
// (i, j) of a width × height equirectangular map (row 0 at the zenith, φ from
// +z towards +x; equirect_direction() in src/render/model_renderer.cpp)
// holds ∫ L(x) ρ_a(r·x) dμ = Σ_lm (2(a+1)/4π) k̂_l L_lm Y_lm(r) for the mirror
// direction r at its centre (Funk–Hecke; the normalised Phong lobe ρ_a of
// skybake/prt.h). RGBA float values, rows in order.
export function glossyMap(light, exponent, width = 128, height = 64) {
  const order = light.order;
  const k = Array.from({ length: order + 1 }, (_, l) => ((2 * (exponent + 1)) / (4 * Math.PI)) * phongLobeZonal(l, exponent));
  const out = new Float32Array(width * height * 4);
  const y = new Float64Array((order + 1) * (order + 1));
  for (let j = 0; j < height; ++j)
    for (let i = 0; i < width; ++i) {
      const phi = 2 * Math.PI * ((i + 0.5) / width - 0.5), theta = (Math.PI * (j + 0.5)) / height;
      shEval(order, Math.sin(theta) * Math.sin(phi), Math.cos(theta), Math.sin(theta) * Math.cos(phi), y);
      const o = 4 * (j * width + i);
      for (let l = 0; l <= order; ++l)
        for (let m = -l; m <= l; ++m) {
          const idx = l * l + l + m, c = light.coefficients[idx];
          for (let ch = 0; ch < 3; ++ch) out[o + ch] += k[l] * c[ch] * y[idx];
        }
      for (let ch = 0; ch < 3; ++ch) out[o + ch] = Math.max(out[o + ch], 0);
      out[o + 3] = 1;
    }
  return out;
}

// glossyMap() as half floats, once per light object and map: the hooks of a
// model's many meshes share one light per sun position.
const glossyCache = new WeakMap();
function glossyTexels(light, exponent, width, height) {
  let perLight = glossyCache.get(light);
  if (!perLight) glossyCache.set(light, (perLight = new Map()));
  const key = `${exponent} ${width}x${height}`;
  let texels = perLight.get(key);
  if (!texels) {
    const map = glossyMap(light, exponent, width, height);
    texels = new Uint16Array(map.length);
    for (let i = 0; i < map.length; ++i) texels[i] = DataUtils.toHalfFloat(map[i]);
    perLight.set(key, texels);
  }
  return texels;
}

// Adds the sky's SH light to `material` (MeshStandardMaterial,
// MeshLambertMaterial, ...) through the baked data of the geometry it draws:
//   mode 'prt': the transfer attributes _prt_0.._prt_{M-1} (three.js's
//               GLTFLoader lower-cases glTF's _PRT_i) and prtGlsl, the text of
//               `skybake prt export BAKED.glb --format glsl-es`;
//   mode 'ao':  the AO attribute `aoAttribute` (default '_ao'; 'color' reads
//               COLOR_0's red; 'aoMap' the material's occlusion texture,
//               per pixel) times the unshadowed SH irradiance, order 2;
//   mode 'none': no sky light, only the albedo attribute below.
// glossy: { attribute: '_shading', exponent: 32, specular: 0.25 } adds, with
// 'prt', the DPRT glossy layer of `skybake view --set shading=dprt`:
// specular · A · glossyMap(light)(r), A the shading coefficient attribute
// (a PRT bake's _SHADING), r the view's mirror direction about the normal.
// albedo: [r, g, b] (linear), or the name of a per-vertex attribute ('_albedo',
// the lower-cased _ALBEDO of a PRT bake), which then also multiplies the
// material's colour for three's own lights. The light is added as emissive
// radiance (albedo × light) so that three's own lights (the sun) keep
// working. Returns an object whose update(light) takes NeuralSky.shLight()'s
// result each frame.
export function skybakeLighting(material, { mode = 'prt', prtGlsl, attributes = 0, order = 3, aoAttribute = '_ao', albedo = [1, 1, 1], glossy = null } = {}) {
  const count = (order + 1) * (order + 1);
  if (mode === 'ao' && order < 2) throw new Error('skybake: ao lighting needs an SH light of order 2 or more');
  const uniformCount = mode === 'prt' ? count : mode === 'ao' ? 9 : 1;
  if (mode === 'prt') {
    checkGlsl(prtGlsl, 'skybake_prt_diffuse');
    if (!Number.isInteger(attributes) || attributes < 1) throw new Error('skybake: prt lighting needs the number of _prt_i attributes');
  } else if (mode !== 'ao' && mode !== 'none') {
    throw new Error(`skybake: lighting mode '${mode}' is not 'prt', 'ao' or 'none'`);
  }
  const albedoAttribute = typeof albedo === 'string' ? albedo : null;
  if (albedoAttribute !== null && !/^[A-Za-z_][A-Za-z0-9_]*$/.test(albedoAttribute))
    throw new Error(`skybake: albedo attribute '${albedoAttribute}' is not a GLSL name`);
  const uniforms = {
    skybakeLight: { value: Array.from({ length: uniformCount }, () => new Vector3()) },
    skybakeAlbedo: { value: albedoAttribute === null ? new Vector3(...albedo) : new Vector3(1, 1, 1) },
  };
  const glossyWidth = 128, glossyHeight = 64;
  if (glossy) {
    const g = { attribute: '_shading', exponent: 32, specular: 0.25, ...glossy };
    if (mode !== 'prt') throw new Error("skybake: the glossy layer goes with mode 'prt'");
    if (!(g.exponent > 0) || !(g.specular >= 0)) throw new Error('skybake: glossy needs an exponent > 0 and a specular ≥ 0');
    if (!/^[A-Za-z_][A-Za-z0-9_]*$/.test(g.attribute)) throw new Error(`skybake: glossy attribute '${g.attribute}' is not a GLSL name`);
    glossy = g;
    const texture = new DataTexture(new Uint16Array(glossyWidth * glossyHeight * 4), glossyWidth, glossyHeight, RGBAFormat, HalfFloatType);
    Object.assign(texture, { magFilter: LinearFilter, minFilter: LinearFilter, wrapS: RepeatWrapping, wrapT: ClampToEdgeWrapping, generateMipmaps: false });
    uniforms.skybakeGlossy = { value: texture };
    uniforms.skybakeSpecular = { value: g.specular };
  }
  material.onBeforeCompile = (shader) => {
    Object.assign(shader.uniforms, uniforms);
    let decl = `uniform vec3 skybakeLight[${uniformCount}];\nvarying vec3 vSkybakeSky;\nvarying vec3 vSkybakeAlbedo;\n`;
    decl += albedoAttribute === null ? 'uniform vec3 skybakeAlbedo;\n' : `attribute vec3 ${albedoAttribute};\n`;
    const albedoValue = albedoAttribute === null ? 'skybakeAlbedo' : albedoAttribute;
    let body;
    if (mode === 'prt') {
      for (let i = 0; i < attributes; ++i) decl += `attribute vec4 _prt_${i};\n`;
      // skybake_prt_diffuse(vec4 prt[M], vec3 light[coefficients], vec3 albedo);
      // with 3 channels each reads its own component of the light.
      body = `{ vec4 skybake_t[${attributes}] = vec4[${attributes}](${Array.from({ length: attributes }, (_, i) => `_prt_${i}`).join(', ')});
        vSkybakeSky = skybake_prt_diffuse(skybake_t, skybakeLight, ${albedoValue}); }`;
      decl += prtGlsl;
    } else if (mode === 'none') {
      body = 'vSkybakeSky = vec3(0.0);';
    } else {
      // 'aoMap': the material's occlusion texture, read per pixel below.
      const ao = aoAttribute === 'color' ? 'color.r' : aoAttribute === 'aoMap' ? '1.0' : aoAttribute;
      // COLOR_0 without vertexColors: three declares no `color`, so declare it
      // here (with vertexColors three would also multiply the sun's light by it).
      if (aoAttribute === 'color') decl += '#if !defined(USE_COLOR) && !defined(USE_COLOR_ALPHA)\nattribute vec3 color;\n#endif\n';
      else if (aoAttribute !== 'aoMap') decl += `attribute float ${aoAttribute};\n`;
      // Irradiance of an order-2 SH light on the normal (Ramamoorthi & Hanrahan's
      // clamped-cosine factors π, 2π/3, π/4), radiance = albedo/π × E × AO.
      body = `{ vec3 n = normalize(mat3(modelMatrix) * objectNormal);
        float x = n.x, y = n.y, z = n.z;
        vec3 E = 3.14159265 * 0.282095 * skybakeLight[0]
          + 2.0943951 * 0.488603 * (y * skybakeLight[1] + z * skybakeLight[2] + x * skybakeLight[3])
          + 0.785398163 * (1.092548 * x * y * skybakeLight[4] + 1.092548 * y * z * skybakeLight[5]
             + 0.315392 * (3.0 * z * z - 1.0) * skybakeLight[6] + 1.092548 * x * z * skybakeLight[7]
             + 0.546274 * (x * x - y * y) * skybakeLight[8]);
        vSkybakeSky = ${albedoValue} / 3.14159265 * max(E, vec3(0.0)) * ${ao}; }`;
    }
    body += `\nvSkybakeAlbedo = ${albedoAttribute === null ? 'vec3(1.0)' : albedoAttribute};`;
    let fragmentDecl = 'varying vec3 vSkybakeSky;\nvarying vec3 vSkybakeAlbedo;\n';
    let fragmentBody = mode === 'ao' && aoAttribute === 'aoMap'
      ? '#ifdef USE_AOMAP\ntotalEmissiveRadiance += vSkybakeSky * ((texture2D(aoMap, vAoMapUv).r - 1.0) * aoMapIntensity + 1.0);\n#else\ntotalEmissiveRadiance += vSkybakeSky;\n#endif'
      : 'totalEmissiveRadiance += vSkybakeSky;';
    if (glossy) {
      decl += `attribute float ${glossy.attribute};\nvarying float vSkybakeA;\n`;
      body += `\nvSkybakeA = ${glossy.attribute};`;
      fragmentDecl += 'varying float vSkybakeA;\nuniform sampler2D skybakeGlossy;\nuniform float skybakeSpecular;\n';
      // The normal turned towards the eye, the mirror direction in world
      // space, and the map's equirectangular look-up (sb_equirect_uv()).
      fragmentBody += `
      { vec3 skybakeN = normalize(normal), skybakeV = normalize(vViewPosition);
        if (dot(skybakeN, skybakeV) < 0.0) skybakeN = -skybakeN;
        vec3 skybakeR = inverseTransformDirection(reflect(-skybakeV, skybakeN), viewMatrix);
        vec2 skybakeUv = vec2(atan(skybakeR.x, skybakeR.z) * 0.159154943 + 0.5, acos(clamp(skybakeR.y, -1.0, 1.0)) * 0.318309886);
        totalEmissiveRadiance += skybakeSpecular * vSkybakeA * texture2D(skybakeGlossy, skybakeUv).rgb; }`;
    }
    shader.vertexShader = decl + shader.vertexShader.replace('#include <begin_vertex>', `#include <begin_vertex>\n${body}`);
    // The per-vertex albedo multiplies the material's colour for three's own
    // lights; the sky's light carries it already.
    shader.fragmentShader = fragmentDecl +
      shader.fragmentShader
        .replace('#include <color_fragment>', '#include <color_fragment>\ndiffuseColor.rgb *= vSkybakeAlbedo;')
        .replace('#include <emissivemap_fragment>', `#include <emissivemap_fragment>\n${fragmentBody}`);
  };
  material.customProgramCacheKey = () => `skybake-${mode}-${attributes}-${order}-${aoAttribute}-${albedoAttribute}-${glossy ? glossy.attribute : ''}`;
  material.needsUpdate = true;
  return {
    uniforms,
    update(light) {
      light.coefficients.forEach((c, i) => {
        if (i < uniforms.skybakeLight.value.length) uniforms.skybakeLight.value[i].set(c[0], c[1], c[2]);
      });
      if (glossy) {
        const texture = uniforms.skybakeGlossy.value;
        texture.image.data = glossyTexels(light, glossy.exponent, glossyWidth, glossyHeight);
        texture.needsUpdate = true;
      }
    },
  };
}
