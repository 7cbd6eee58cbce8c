// The JavaScript forward pass against the library's: `skybake sky eval
// --model` on the same samples, relative error |ΔI|/|I| (RGB norms). The
// JavaScript rounds every operation to float32 in the order of the library's
// scalar pass (src/neural/mlp_hd.h); `sky eval` runs the batch pass (Eigen),
// which sums in its own order and differs from the scalar one by a few float
// ulps of the encoded outputs; log decoding multiplies those by about 15. So
// the bound is 2e-5: measured, 4.2e-6 (paper), 4.0e-7 (linear brightness),
// 1.1e-5 (the default network).
// The shared test vectors (tests/data/neural/test_vectors.json, which the
// C++ test NeuralSky.SharedTestVectorsAreTheScalarPass checks against the
// library's scalar pass) are the tighter check: within 1e-5 relative.
// Needs SKYBAKE_CLI (the skybake executable) and SKYBAKE_TEST_DATA (the
// repository's tests/data); ctest's web.neural_sky sets both.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

import { NeuralSky } from '../src/neural_sky.js';

const cli = process.env.SKYBAKE_CLI;
const data = process.env.SKYBAKE_TEST_DATA;

// Valid samples (a Gram determinant ≥ 0), from a fixed seed: cosines in
// [−1, 1], densities in (0, 1], and the flight's thin air (density down to 1e-3).
function samples(count, seed) {
  let s = seed >>> 0;
  const next = () => {
    s = (Math.imul(s, 1664525) + 1013904223) >>> 0;
    return s / 4294967296;
  };
  const out = [];
  while (out.length < count) {
    const a = 2 * next() - 1, b = 2 * next() - 1, c = 2 * next() - 1;
    const rho = out.length % 4 === 0 ? Math.exp(-7 * next()) : 1 - next();
    if (1 + 2 * a * b * c - a * a - b * b - c * c >= 1e-6 && rho > 0) out.push([a, b, c, rho]);
  }
  return out;
}

function libraryRadiance(model, rows, extra = []) {
  const dir = mkdtempSync(join(tmpdir(), 'skybake-web-'));
  try {
    const input = join(dir, 'in.csv'), output = join(dir, 'out.csv');
    writeFileSync(input, 'cos_view_zenith,cos_view_sun,cos_sun_zenith,density\n' +
      rows.map((r) => r.map((x) => x.toPrecision(9)).join(',')).join('\n') + '\n');
    execFileSync(cli, ['--quiet', 'sky', 'eval', '--model', model, '--input', input, '--output', output, ...extra]);
    const lines = readFileSync(output, 'utf8').trim().split('\n').slice(1);
    return { rows: rows.map((r) => r.map((x) => Number(x.toPrecision(9)))), ref: lines.map((l) => l.split(',').map(Number)) };
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
}

for (const [file, what, aerosol] of [
  ['neural/v1_paper.json', 'the seed topology, seed inputs, log brightness'],
  ['neural/v1_shared_linear.json', 'a shared network, linear brightness'],
  ['neural/v3_earth_default.json', 'horizon inputs, phase-factored outputs'],
  ['neural/v3_earth_residual.json', 'the default: horizon inputs, residual outputs'],
  ['neural/v3_earth_multiple.json', 'multiple scattering: residual outputs and their term, log-encoded'],
  ['neural/v3_earth_multiple_march.json', 'the default with multiple scattering: its term a correction of the isotropic march'],
  ['neural/v3_earth_family.json', 'an aerosol family at 5 times the aerosol', 5],
  ['neural/v3_earth_family.json', 'an aerosol family at its hazy end, 32 times', 32],
]) {
  test(`${file} (${what}) matches the library`, { skip: !cli || !data ? 'SKYBAKE_CLI and SKYBAKE_TEST_DATA not set' : false }, () => {
    const model = join(data, file);
    const sky = new NeuralSky(readFileSync(model, 'utf8'));
    if (aerosol !== undefined) sky.aerosol = aerosol;
    const { rows, ref } = libraryRadiance(model, samples(3000, 17), aerosol !== undefined ? ['--aerosol', String(aerosol)] : []);
    assert.equal(ref.length, rows.length);
    let worst = 0, lit = 0;
    rows.forEach((r, i) => {
      const got = sky.radiance(...r);
      const e = ref[i];
      const n = Math.hypot(...e);
      const d = Math.hypot(got[0] - e[0], got[1] - e[1], got[2] - e[2]);
      if (n === 0) {
        assert.ok(d <= 1e-6 * sky.maxN, `night sample ${i}: ${got}`);
        return;
      }
      ++lit;
      worst = Math.max(worst, d / n);
    });
    assert.ok(lit > 1000, `${lit} lit samples`);
    assert.ok(worst < 2e-5, `worst relative error ${worst}`);
    console.log(`${file}: max relative error ${worst.toExponential(2)} over ${lit} lit samples`);
  });
}

test('an aerosol amount outside the family, or for a network without one, is one clear error', { skip: !data ? 'SKYBAKE_TEST_DATA not set' : false }, () => {
  const family = new NeuralSky(readFileSync(join(data, 'neural', 'v3_earth_family.json'), 'utf8'));
  assert.throws(() => { family.aerosol = 40; }, /outside the family's range \[1, 32\]/);
  const plain = new NeuralSky(readFileSync(join(data, 'neural', 'v3_earth_residual.json'), 'utf8'));
  assert.throws(() => { plain.aerosol = 2; }, /not of an aerosol family/);
  assert.equal(plain.aerosol, 1);
});

test('a file that is not a weights file is one clear error', () => {
  assert.throws(() => new NeuralSky('{"format": "something-else"}'), /not a weights file/);
  assert.throws(() => new NeuralSky('not json'), SyntaxError);
  const broken = { format: 'skybake-neural-sky', topology: { kind: 'shared', hidden: [4] }, encoding: { max_n: 1, log_range: 13 },
    atmosphere: { planet_radius_km: 6360, top_radius_km: 6420 }, weights: [[1, 2, 3]] };
  assert.throws(() => new NeuralSky(broken), /each sub-network has 40 weights/);
});

test('a marched multiple-scattering term with a bad psi is one clear error, as in the library', { skip: !data ? 'SKYBAKE_TEST_DATA not set' : false }, () => {
  const good = JSON.parse(readFileSync(join(data, 'neural', 'v3_earth_multiple_march.json'), 'utf8'));
  const bad = (edit) => { const d = structuredClone(good); edit(d.encoding); return d; };
  assert.throws(() => new NeuralSky(bad((e) => { e.multiple_psi.log_psi[1][3] = 1e9; })), /log_psi must be numbers in \[-1e4, 1e4\]/);
  assert.throws(() => new NeuralSky(bad((e) => { e.multiple_psi.log_psi.pop(); })), /3 rows of 21 coefficients/);
  assert.throws(() => new NeuralSky(bad((e) => { e.multiple_psi.mu_s_min = 0.9; })), /mu_s_min must be in/);
  assert.throws(() => new NeuralSky(bad((e) => { delete e.multiple_max; })), /needs multiple_max/);
});

test('the shared test vectors: the library\'s scalar pass to 1e-5 relative', { skip: !data ? 'SKYBAKE_TEST_DATA not set' : false }, () => {
  const doc = JSON.parse(readFileSync(join(data, 'neural', 'test_vectors.json'), 'utf8'));
  assert.equal(doc.format, 'skybake-neural-test-vectors');
  for (const [file, rows] of Object.entries(doc.networks)) {
    const sky = new NeuralSky(readFileSync(join(data, 'neural', file), 'utf8'));
    let worst = 0, lit = 0;
    for (const r of rows) {
      const got = sky.radiance(r[0], r[1], r[2], r[3]);
      const n = Math.hypot(r[4], r[5], r[6]);
      const d = Math.hypot(got[0] - r[4], got[1] - r[5], got[2] - r[6]);
      if (n === 0) {
        assert.ok(d <= 1e-6 * sky.maxN, `${file}: night sample ${r}: ${got}`);
        continue;
      }
      ++lit;
      worst = Math.max(worst, d / n);
    }
    console.log(`${file}: max relative error ${worst.toExponential(2)} against the scalar pass over ${lit} lit vectors`);
    assert.ok(lit > 100, `${file}: ${lit} lit vectors`);
    assert.ok(worst < 1e-5, `${file}: worst relative error ${worst}`);
  }
});
