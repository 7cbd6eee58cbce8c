// The sky as spherical-harmonic light, projected in JavaScript from the
// network for the current sun (per frame in a browser), as `skybake sky sh
// --model` does: skybake's real SH (Ramamoorthi & Hanrahan's table without the
// Condon–Shortley phase, Y_1,-1 ∝ y, Y_10 ∝ z, Y_11 ∝ x, index l² + l + m) in
// the glTF frame (zenith +y; sun azimuth 0 towards +z, 90° towards +x), with
// skybake's default rule `horizon:32x36`: Gauss–Legendre nodes in y on each
// side of the horizon times uniform azimuths, so that the step of the sky at
// the horizon is integrated exactly (a rule with points on the horizon reads
// it at full brightness). Radiance is per unit sun irradiance; the ground
// itself is not added (below the horizon: the air between the observer and
// the ground).

// Gauss–Legendre nodes and weights on (0, 1), weights summing to 1 (Newton's
// method on the Legendre polynomial from the usual cosine guesses).
export function gaussLegendreUnit(n) {
  const nodes = new Float64Array(n), weights = new Float64Array(n);
  for (let i = 0; i < n; ++i) {
    let x = Math.cos((Math.PI * (i + 0.75)) / (n + 0.5));
    let dp = 1;
    for (let it = 0; it < 100; ++it) {
      let p0 = 1, p1 = x;
      for (let k = 2; k <= n; ++k) {
        const p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const pn = n === 1 ? x : p1, pm = n === 1 ? 1 : p0;
      dp = (n * (x * pn - pm)) / (x * x - 1);
      const dx = pn / dp;
      x -= dx;
      if (Math.abs(dx) < 1e-16) break;
    }
    nodes[n - 1 - i] = 0.5 * (x + 1); // ascending on (0, 1)
    weights[n - 1 - i] = 1 / ((1 - x * x) * dp * dp); // (2 / ((1 − x²) P'²)) / 2
  }
  return { nodes, weights };
}

// skybake's horizon:NxM rule: points (unit, glTF frame) and weights summing to 1.
export function horizonRule(n = 32, m = 36) {
  const gl = gaussLegendreUnit(n);
  const points = [], weights = [];
  for (const side of [1, -1])
    for (let i = 0; i < n; ++i) {
      const y = side * gl.nodes[i];
      const r = Math.sqrt(Math.max(0, 1 - y * y));
      for (let j = 0; j < m; ++j) {
        const phi = (2 * Math.PI * (j + 0.5)) / m;
        points.push([r * Math.cos(phi), y, r * Math.sin(phi)]);
        weights.push((0.5 * gl.weights[i]) / m);
      }
    }
  return { points, weights };
}

// All real SH Y_lm(x, y, z), l ≤ lmax, at index l² + l + m (sphere::sh_eval_hd).
export function shEval(lmax, x, y, z, out = new Float64Array((lmax + 1) * (lmax + 1))) {
  let pmm = 0.28209479177387814;
  let c = 1, s = 0;
  for (let m = 0; m <= lmax; ++m) {
    if (m > 0) {
      pmm *= Math.sqrt((2 * m + 1) / (2 * m));
      const cn = x * c - y * s;
      s = x * s + y * c;
      c = cn;
    }
    let q2 = 0, q1 = pmm;
    const sqrt2 = m === 0 ? 1 : Math.SQRT2;
    for (let l = m; l <= lmax; ++l) {
      let q;
      if (l === m) q = q1;
      else if (l === m + 1) {
        q = z * q1 * Math.sqrt(2 * m + 3);
        q2 = q1;
        q1 = q;
      } else {
        const ll = l * l, mm = m * m, l1 = l - 1;
        const a = Math.sqrt((4 * ll - 1) / (ll - mm));
        const b = Math.sqrt((l1 * l1 - mm) / (4 * l1 * l1 - 1));
        q = (z * q1 - q2 * b) * a;
        q2 = q1;
        q1 = q;
      }
      const centre = l * l + l;
      if (m === 0) out[centre] = q;
      else {
        out[centre + m] = q * c * sqrt2;
        out[centre - m] = q * s * sqrt2;
      }
    }
  }
  return out;
}

// Unit direction towards the sun (glTF frame).
export function sunDirection(elevationDeg, azimuthDeg) {
  const e = (elevationDeg * Math.PI) / 180, a = (azimuthDeg * Math.PI) / 180;
  return [Math.cos(e) * Math.sin(a), Math.sin(e), Math.cos(e) * Math.cos(a)];
}

// Keeps the rule's SH table, so that each frame costs one network evaluation
// per rule point (2,304 by default) and a multiply-add per coefficient.
export class SkyProjector {
  constructor(order = 3, rule = horizonRule()) {
    if (!Number.isInteger(order) || order < 0 || order > 8) throw new Error('SH order must be 0 to 8');
    this.order = order;
    this.count = (order + 1) * (order + 1);
    this.points = rule.points;
    this.table = new Float64Array(rule.points.length * this.count);
    const y = new Float64Array(this.count);
    rule.points.forEach((p, k) => {
      shEval(order, p[0], p[1], p[2], y);
      for (let i = 0; i < this.count; ++i) this.table[k * this.count + i] = 4 * Math.PI * rule.weights[k] * y[i];
    });
  }

  // SH coefficients [[r, g, b], ...] of the sky of `sky` (a NeuralSky) with
  // the sun at elevation and azimuth (degrees), for an observer whose relative
  // density is `density` (1 at sea level).
  project(sky, elevationDeg, azimuthDeg, density = 1) {
    const sun = sunDirection(elevationDeg, azimuthDeg);
    const clamp = (v) => (v < -1 ? -1 : v > 1 ? 1 : v);
    const coeffs = Array.from({ length: this.count }, () => [0, 0, 0]);
    this.points.forEach((p, k) => {
      const L = sky.radiance(clamp(p[1]), clamp(p[0] * sun[0] + p[1] * sun[1] + p[2] * sun[2]), clamp(sun[1]), density);
      for (let i = 0; i < this.count; ++i) {
        const w = this.table[k * this.count + i];
        coeffs[i][0] += L[0] * w;
        coeffs[i][1] += L[1] * w;
        coeffs[i][2] += L[2] * w;
      }
    });
    return { order: this.order, coefficients: coeffs, sunDirection: sun };
  }
}
