// Types of skybake-web.
export { NeuralSky, NeuralSkyJson } from './neural_sky.js';

export interface SphereRule {
  points: [number, number, number][];
  weights: number[];
}
export interface ShLight {
  order: number;
  /** (order + 1)² coefficients, [r, g, b] each, skybake's SH convention, glTF frame (zenith +y). */
  coefficients: [number, number, number][];
  sunDirection: [number, number, number];
}
export declare function gaussLegendreUnit(n: number): { nodes: Float64Array; weights: Float64Array };
/** skybake's horizon:NxM rule (default 32 x 36). */
export declare function horizonRule(n?: number, m?: number): SphereRule;
export declare function shEval(lmax: number, x: number, y: number, z: number, out?: Float64Array): Float64Array;
export declare function sunDirection(elevationDeg: number, azimuthDeg: number): [number, number, number];
export declare class SkyProjector {
  constructor(order?: number, rule?: SphereRule);
  readonly order: number;
  project(sky: import('./neural_sky.js').NeuralSky, elevationDeg: number, azimuthDeg: number, density?: number): ShLight;
}
