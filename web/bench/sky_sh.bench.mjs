// Time of one SH projection of the network's sky (SkyProjector, order 4,
// horizon:32x36), against its baseline measured in the same run: the same
// 2,304 network evaluations alone. node web/bench/sky_sh.bench.mjs [weights.json]
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

import { NeuralSky, SkyProjector, horizonRule, sunDirection } from '../src/index.js';

const model = process.argv[2] ?? fileURLToPath(new URL('../../tests/data/neural/v3_earth_default.json', import.meta.url));
const sky = new NeuralSky(readFileSync(model, 'utf8'));
const projector = new SkyProjector(4);
const points = horizonRule().points;

function time(label, fn, n = 100) {
  for (let i = 0; i < 10; ++i) fn(i); // warm up the JIT
  const t0 = performance.now();
  for (let i = 0; i < n; ++i) fn(i);
  const ms = (performance.now() - t0) / n;
  console.log(`${label}: ${ms.toFixed(2)} ms`);
  return ms;
}

const base = time('2,304 network evaluations (baseline)', (i) => {
  const s = sunDirection(10 + 0.1 * i, 30);
  for (const p of points) sky.radiance(p[1], p[0] * s[0] + p[1] * s[1] + p[2] * s[2], s[1], 1);
});
const full = time('SkyProjector.project, order 4', (i) => projector.project(sky, 10 + 0.1 * i, 30));
console.log(`projection / baseline: ${(full / base).toFixed(2)} (node ${process.version})`);
