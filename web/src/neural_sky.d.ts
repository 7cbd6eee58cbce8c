// Types of src/neural_sky.js.

/** The parsed weights file of `skybake sky train` (format "skybake-neural-sky"). */
export type NeuralSkyJson = Record<string, unknown>;

export declare class NeuralSky {
  /** From the weights file's text or parsed object; throws an Error naming the field that is wrong. */
  constructor(json: string | NeuralSkyJson);
  readonly topology: string;
  readonly weightCount: number;
  readonly inputs: 'seed' | 'horizon';
  readonly outputKind: 'radiance' | 'phase-factored';
  readonly brightness: 'log' | 'linear';
  /** The network's four inputs for the sky function's arguments. */
  encodeInputs(cosViewZenith: number, cosViewSun: number, cosSunZenith: number, density: number): number[];
  /** The encoded outputs for four inputs. */
  forward(inputs: ArrayLike<number>): Float32Array;
  /** Radiance per unit sun irradiance (1/sr), linear RGB. */
  radiance(cosViewZenith: number, cosViewSun: number, cosSunZenith: number, density: number): [number, number, number];
}
