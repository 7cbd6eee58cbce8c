// Types of skybake-web/three.
import type { Mesh, Material, BoxGeometry, ShaderMaterial, IUniform, Vector3 } from 'three';
import type { NeuralSky as Network, NeuralSkyJson } from './neural_sky.js';
import type { ShLight } from './index.js';

/** A drop-in for three.js's Sky: set material.uniforms.sunPosition (or setSun()). */
export declare class NeuralSky extends Mesh<BoxGeometry, ShaderMaterial> {
  /**
   * @param weights the weights file of `skybake sky train` (text, parsed JSON or a skybake-web NeuralSky)
   * @param glsl `skybake sky export` of the same file with `--format glsl-es`
   */
  constructor(weights: string | NeuralSkyJson | Network, glsl: string, options?: { order?: number });
  readonly isSky: true;
  readonly network: Network;
  /** Uniforms: sunPosition, up (default +y), density (1 at sea level), sunIrradiance (scale of the output). */
  setSun(elevationDeg: number, azimuthDeg: number): this;
  sunAngles(): { elevation: number; azimuth: number };
  /** The sky's SH light for the current sun, times sunIrradiance. */
  shLight(): ShLight;
}

export interface SkybakeLightingOptions {
  /** 'prt': the _prt_i attributes through prtGlsl; 'ao': an AO attribute times the unshadowed order-2 light; 'none': only a per-vertex albedo. */
  mode?: 'prt' | 'ao' | 'none';
  /** `skybake prt export BAKED.glb --format glsl-es` */
  prtGlsl?: string;
  /** Number of _prt_i attributes (the sidecar's "attributes"). */
  attributes?: number;
  order?: number;
  /** The AO: '_ao' (glTF _AO, lower-cased by GLTFLoader), 'color' (COLOR_0's red) or 'aoMap' (the material's occlusion texture). */
  aoAttribute?: string;
  /** Linear RGB, or a per-vertex attribute ('_albedo': a PRT bake's _ALBEDO) that also multiplies the material's colour. */
  albedo?: [number, number, number] | string;
  /** With mode 'prt': the DPRT glossy layer, specular · A · glossyMap(light)(mirror direction). */
  glossy?: { attribute?: string; exponent?: number; specular?: number } | null;
}

/** k̂_l = 2π ∫_0^1 t^a P_l(t) dt, the Phong lobe's zonal factors. */
export declare function phongLobeZonal(l: number, exponent: number): number;

/** The glossy layer of an SH light: an equirectangular RGBA map (row 0 at the zenith) by mirror direction. */
export declare function glossyMap(light: ShLight, exponent: number, width?: number, height?: number): Float32Array;

export declare function skybakeLighting(
  material: Material,
  options?: SkybakeLightingOptions,
): { uniforms: Record<string, IUniform>; update(light: ShLight): void };
