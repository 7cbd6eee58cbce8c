// The DPRT glossy layer of skybake-web/three against closed forms and brute
// force: the Phong lobe's zonal factors (Ramamoorthi & Hanrahan's clamped
// cosine at a = 1; Simpson's rule at a = 32) and glossyMap() against the
// lobe integrated over the sphere around each texel's mirror direction.
import { test } from 'node:test';
import assert from 'node:assert/strict';

import { glossyMap, phongLobeZonal } from '../src/three.js';
import { shEval } from '../src/index.js';

test('the Phong zonal factors: the clamped cosine, and a = 32 by Simpson', () => {
  const want = [Math.PI, (2 * Math.PI) / 3, Math.PI / 4, 0, -Math.PI / 24];
  want.forEach((w, l) => assert.ok(Math.abs(phongLobeZonal(l, 1) - w) < 1e-12, `l ${l}: ${phongLobeZonal(l, 1)}`));
  const legendre = (l, t) => {
    let p0 = 1, p1 = t;
    if (l === 0) return 1;
    for (let n = 2; n <= l; ++n) [p0, p1] = [p1, ((2 * n - 1) * t * p1 - (n - 1) * p0) / n];
    return p1;
  };
  for (const a of [32, 7.5]) {
    for (let l = 0; l <= 6; ++l) {
      const n = 20000, h = 1 / n;
      let s = 0;
      for (let i = 0; i <= n; ++i) {
        const t = i * h, w = i === 0 || i === n ? 1 : i % 2 ? 4 : 2;
        s += w * t ** a * legendre(l, t);
      }
      const simpson = ((2 * Math.PI * h) / 3) * s;
      assert.ok(Math.abs(phongLobeZonal(l, a) - simpson) < 1e-10, `a ${a} l ${l}: ${phongLobeZonal(l, a)} vs ${simpson}`);
    }
  }
});

test('glossyMap is the normalised Phong lobe integrated against the SH light', () => {
  // A fixed light of order 3 (positive, so that the clamp at 0 does not act).
  const order = 3, coefficients = [];
  for (let i = 0; i < 16; ++i) coefficients.push([i === 0 ? 3 : 0.3 * Math.sin(i), i === 0 ? 2.5 : 0.2 * Math.cos(i), i === 0 ? 2 : 0.1 * Math.sin(2 * i)]);
  const light = { order, coefficients };
  const [W, H] = [16, 8];
  for (const a of [4, 32]) {
    const map = glossyMap(light, a, W, H);
    for (const [i, j] of [[0, 0], [5, 3], [12, 6], [8, 7]]) {
      const phi = 2 * Math.PI * ((i + 0.5) / W - 0.5), theta = (Math.PI * (j + 0.5)) / H;
      const r = [Math.sin(theta) * Math.sin(phi), Math.cos(theta), Math.sin(theta) * Math.cos(phi)];
      // A frame (t, b, r) and a polar grid around r: midpoint in cos θ, uniform φ.
      const t = Math.abs(r[1]) < 0.9 ? [r[2], 0, -r[0]] : [0, -r[2], r[1]];
      const tl = Math.hypot(...t);
      t.forEach((_, k) => (t[k] /= tl));
      const b = [r[1] * t[2] - r[2] * t[1], r[2] * t[0] - r[0] * t[2], r[0] * t[1] - r[1] * t[0]];
      const [nc, np] = [800, 128];
      const sum = [0, 0, 0], y = new Float64Array(16);
      for (let c = 0; c < nc; ++c) {
        const ct = (c + 0.5) / nc, st = Math.sqrt(1 - ct * ct), lobe = 2 * (a + 1) * ct ** a;
        for (let p = 0; p < np; ++p) {
          const f = (2 * Math.PI * (p + 0.5)) / np;
          const x = [0, 1, 2].map((k) => st * Math.cos(f) * t[k] + st * Math.sin(f) * b[k] + ct * r[k]);
          shEval(order, x[0], x[1], x[2], y);
          for (let ch = 0; ch < 3; ++ch) {
            let L = 0;
            for (let q = 0; q < 16; ++q) L += coefficients[q][ch] * y[q];
            sum[ch] += (lobe * L) / (nc * np) / 2; // dμ = dω/4π = d(cos θ) dφ / 4π
          }
        }
      }
      for (let ch = 0; ch < 3; ++ch) {
        const got = map[4 * (j * W + i) + ch];
        assert.ok(Math.abs(got - sum[ch]) < 2e-4 * Math.abs(sum[ch]) + 1e-6, `a ${a} texel ${i},${j} channel ${ch}: ${got} vs ${sum[ch]}`);
      }
    }
  }
});
