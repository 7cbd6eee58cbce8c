// The sky's SH light projected in JavaScript (SkyProjector) against `skybake
// sky sh --model` for the same network and sun, and the pieces against
// closed forms: Gauss–Legendre integrates polynomials of degree 2n − 1, the
// horizon rule integrates Y_lm Y_l'm' to δ (orthonormality).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

import { NeuralSky, SkyProjector, gaussLegendreUnit, horizonRule, shEval } from '../src/index.js';

const cli = process.env.SKYBAKE_CLI;
const data = process.env.SKYBAKE_TEST_DATA;
const needsCli = !cli || !data ? 'SKYBAKE_CLI and SKYBAKE_TEST_DATA not set' : false;

test('Gauss–Legendre on (0, 1) integrates x^k exactly up to k = 2n − 1', () => {
  for (const n of [1, 2, 5, 32]) {
    const { nodes, weights } = gaussLegendreUnit(n);
    for (let k = 0; k <= 2 * n - 1; ++k) {
      let s = 0;
      nodes.forEach((x, i) => (s += weights[i] * x ** k));
      assert.ok(Math.abs(s - 1 / (k + 1)) < 1e-13, `n ${n} k ${k}: ${s}`);
    }
  }
});

test("the horizon rule keeps skybake's SH orthonormal up to order 8", () => {
  const rule = horizonRule(32, 36);
  const n = 81;
  const gram = new Float64Array(n * n);
  const y = new Float64Array(n);
  rule.points.forEach((p, k) => {
    shEval(8, p[0], p[1], p[2], y);
    for (let i = 0; i < n; ++i)
      for (let j = 0; j < n; ++j) gram[i * n + j] += 4 * Math.PI * rule.weights[k] * y[i] * y[j];
  });
  for (let i = 0; i < n; ++i)
    for (let j = 0; j < n; ++j) assert.ok(Math.abs(gram[i * n + j] - (i === j ? 1 : 0)) < 1e-10, `${i} ${j}`);
  // Y_1,-1 ∝ y, Y_10 ∝ z, Y_11 ∝ x (skybake's convention, no Condon–Shortley phase).
  const c = Math.sqrt(3 / (4 * Math.PI));
  const v = shEval(1, 0.36, 0.48, 0.8);
  assert.ok(Math.abs(v[1] - c * 0.48) < 1e-15 && Math.abs(v[2] - c * 0.8) < 1e-15 && Math.abs(v[3] - c * 0.36) < 1e-15);
});

test('SkyProjector matches skybake sky sh --model', { skip: needsCli }, () => {
  const model = join(data, 'neural/v3_earth_default.json');
  const sky = new NeuralSky(readFileSync(model, 'utf8'));
  const projector = new SkyProjector(4);
  const dir = mkdtempSync(join(tmpdir(), 'skybake-web-sh-'));
  try {
    for (const [elevation, azimuth] of [[45, 30], [5, -60], [-4, 120]]) {
      const out = join(dir, 'light.json');
      execFileSync(cli, ['--quiet', 'sky', 'sh', '--model', model, '--sun-elevation-deg', String(elevation),
        '--sun-azimuth-deg', String(azimuth), '--order', '4', '-o', out]);
      const ref = JSON.parse(readFileSync(out, 'utf8')).coefficients;
      const got = projector.project(sky, elevation, azimuth).coefficients;
      assert.equal(got.length, ref.length);
      for (let ch = 0; ch < 3; ++ch) {
        let d = 0, n = 0;
        ref.forEach((r, i) => {
          d += (got[i][ch] - r[ch]) ** 2;
          n += r[ch] ** 2;
        });
        const rel = Math.sqrt(d / n);
        console.log(`sun ${elevation} deg, azimuth ${azimuth}: channel ${ch} relative L2 ${rel.toExponential(2)}`);
        assert.ok(rel < 1e-4, `sun ${elevation}/${azimuth} channel ${ch}: relative L2 ${rel}`);
      }
    }
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});

test('a frame costs one network evaluation per rule point', { skip: needsCli }, () => {
  const sky = new NeuralSky(readFileSync(join(data, 'neural/v3_earth_default.json'), 'utf8'));
  let calls = 0;
  const counted = { radiance: (...a) => (++calls, sky.radiance(...a)) };
  new SkyProjector(4).project(counted, 20, 0);
  assert.equal(calls, 2 * 32 * 36);
});
