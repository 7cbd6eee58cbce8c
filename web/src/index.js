// skybake-web: the neural sky of `skybake sky train` and its SH light, in JavaScript.
export { NeuralSky } from './neural_sky.js';
export { SkyProjector, horizonRule, gaussLegendreUnit, shEval, sunDirection } from './sky_sh.js';
