// The neural sky of `skybake sky train` in JavaScript: reads the weights file
// (the same JSON) and evaluates the network, operation for operation as
// src/neural/mlp_hd.h does in C++ (Pietras & Rudnicki, seed 000, sections III
// and VI). Every operation is rounded to float32 (Math.fround), as the C++
// pass and the GPU's shaders compute: near the horizon the input encoding
// subtracts nearly equal numbers, and double precision there would give a
// different sky. test/neural_sky.test.mjs checks it against `skybake sky
// eval --model` (within 2e-5 relative; 4e-7 to 1.1e-5 measured).
const f = Math.fround;

const ENCODE_OFFSET = 0.05;
const ENCODE_SCALE = 0.9;
const HORIZON_GAP = 0.25;
const HORIZON_SPAN = 1 - HORIZON_GAP;

// Phase functions (1/sr) of sky::phase_value, by the names of the weights file.
// In float32, operation for operation as sky::phase_value.
const PI = f(Math.PI);
const PHASES = {
  none: () => 0,
  rayleigh: (g, mu) => f(f(3 / f(16 * PI)) * f(1 + f(mu * mu))),
  'henyey-greenstein': (g, mu) => {
    const d = f(f(f(1 + f(g * g)) - f(f(2 * g) * mu)));
    return f(f(f(f(0.25) / PI) * f(1 - f(g * g))) / f(d * f(Math.sqrt(d))));
  },
  'cornette-shanks': (g, mu) => {
    const d = f(f(1 + f(g * g)) - f(f(2 * g) * mu));
    const num = f(f(3 * f(1 - f(g * g))) * f(1 + f(mu * mu)));
    return f(num / f(f(f(f(8 * PI) * f(2 + f(g * g))) * d) * f(Math.sqrt(d))));
  },
  'pietras-rudnicki-mie': (g, mu) => {
    const d = f(f(1 + f(g * g)) - f(f(2 * g) * mu));
    return f(f(1 - f(g * g)) / f(f(f(16 * PI) * d) * f(Math.sqrt(d))));
  },
};
PHASES['seed-mie'] = PHASES['pietras-rudnicki-mie'];

function fail(what) {
  throw new Error(`skybake neural sky: ${what}`);
}

function finiteNumber(x, what) {
  if (typeof x !== 'number' || !Number.isFinite(x)) fail(`${what} must be a finite number`);
  return x;
}

// f(x) = 1/(1 + 2^(2x)), the seed's activation.
function activation(x) {
  return f(1 / f(1 + f(Math.pow(2, f(2 * x)))));
}

const INV_SCALE = f(1 / ENCODE_SCALE);

function decodeUnit(x) {
  const v = f(f(x - f(ENCODE_OFFSET)) * INV_SCALE);
  return v > 0 ? v : 0;
}

function decodeLog(x, max, logRange) {
  const v = f(f(x - f(ENCODE_OFFSET)) * INV_SCALE);
  return v > 0 ? f(max * f(Math.exp(f(logRange * f(v - 1))))) : 0;
}

// Residual outputs: mlp_hd.h's analytic single scattering, in float32
// operation for operation (kResidualSteps, kResidualRange there).
const RESIDUAL_STEPS = 4;
const RESIDUAL_SCALE = f(2 / f(0.5 * ENCODE_SCALE));
const MULTIPLE_LOG_RANGE = f(27.6310211); // kMultipleLogRange: 12 decades
// Or the term as a correction of an isotropic march (kMultipleSteps, and the
// degrees of ln psi's polynomial: kPsiAltitudeDegree, kPsiSunDegree).
const MULTIPLE_STEPS = 4;
const PSI_ALTITUDE_DEGREE = 2, PSI_SUN_DEGREE = 6;
const PSI_COEFFICIENTS = (PSI_ALTITUDE_DEGREE + 1) * (PSI_SUN_DEGREE + 1);

function periapsisAltitude(h, R0, cosChi) {
  const s2 = f(f(1 - cosChi) * f(1 + cosChi));
  const s = f(Math.sqrt(s2 > 0 ? s2 : 0));
  const h0 = f(f(h * s) - f(f(R0 * f(cosChi * cosChi)) / f(1 + s)));
  return h0 > 0 ? h0 : 0;
}

function chapman(h, R0, H, cosChi) {
  const k = f(Math.sqrt(f(f(R0 + h) / H))), kc = f(k * cosChi);
  return f(k / f(f(f(0.661) * kc) + f(f(0.339) * f(Math.sqrt(f(f(kc * kc) + f(5.51)))))));
}

function chapmanDepth(h, R0, H, cosChi, rhoH) {
  if (cosChi >= 0) return f(f(H * rhoH) * chapman(h, R0, H, cosChi));
  const h0 = periapsisAltitude(h, R0, cosChi);
  const whole = f(f(2 * f(Math.exp(f(-h0 / H)))) * chapman(h0, R0, H, 0));
  return f(H * f(whole - f(rhoH * chapman(h, R0, H, -cosChi))));
}

function chapmanSegment(R0, H, ha, ca, rhoA, hb, cb, rhoB) {
  const fa = f(f(H * rhoA) * chapman(ha, R0, H, Math.abs(ca)));
  const fb = f(f(H * rhoB) * chapman(hb, R0, H, Math.abs(cb)));
  if (ca >= 0) return f(fa - fb);
  if (cb < 0) return f(fb - fa);
  const h0 = periapsisAltitude(ha, R0, ca);
  const whole = f(f(f(2 * H) * f(Math.exp(f(-h0 / H)))) * chapman(h0, R0, H, 0));
  return f(f(whole - fa) - fb);
}

export class NeuralSky {
  // `json`: the weights file's text or its parsed object. Throws an Error
  // naming the field for a file that is not a skybake neural sky.
  constructor(json) {
    const d = typeof json === 'string' ? JSON.parse(json) : json;
    if (!d || d.format !== 'skybake-neural-sky') fail('not a weights file (format is not "skybake-neural-sky")');
    const t = d.topology ?? fail('no topology');
    const hidden = t.hidden;
    if (!Array.isArray(hidden) || hidden.some((h) => !Number.isInteger(h) || h < 1 || h > 128))
      fail('topology.hidden must be a list of layer widths 1 to 128');
    const e = d.encoding ?? fail('no encoding');
    this.inputs = e.inputs ?? 'seed';
    this.outputKind = e.outputs ?? 'radiance';
    this.brightness = e.brightness ?? 'log';
    if (!['seed', 'horizon'].includes(this.inputs)) fail(`encoding.inputs '${this.inputs}' is unknown`);
    if (!['radiance', 'phase-factored', 'residual'].includes(this.outputKind))
      fail(`encoding.outputs '${this.outputKind}' is unknown`);
    if (!['log', 'linear'].includes(this.brightness)) fail(`encoding.brightness '${this.brightness}' is unknown`);
    this.maxN = finiteNumber(e.max_n, 'encoding.max_n');
    this.logRange = finiteNumber(e.log_range, 'encoding.log_range');
    this.terms = [];
    const factored = this.outputKind !== 'radiance';
    if (factored) {
      for (const term of e.terms ?? fail('encoding.terms is missing')) {
        const phase = PHASES[term.phase] ?? fail(`phase '${term.phase}' is unknown`);
        this.terms.push({ phase, g: finiteNumber(term.g ?? 0, 'terms.g'), max: term.max_s.map((m) => finiteNumber(m, 'terms.max_s')),
          component: term.component });
      }
    }
    // Residual outputs of a sky with multiple scattering: the multiply scattered light, after the terms.
    this.multipleMax = null;
    if (e.multiple_max !== undefined) {
      if (this.outputKind !== 'residual' || !Array.isArray(e.multiple_max) || e.multiple_max.length !== 3)
        fail('encoding.multiple_max must be [r, g, b], with residual outputs');
      this.multipleMax = e.multiple_max.map((m) => finiteNumber(m, 'encoding.multiple_max'));
    }
    // Or, marched: ln psi's polynomial (mlp_hd.h's psi_log) and its lowest sun cosine.
    this.psi = null;
    if (e.multiple_psi !== undefined) {
      const rows = e.multiple_psi.log_psi;
      if (!this.multipleMax || !Array.isArray(rows) || rows.length !== 3 ||
          rows.some((row) => !Array.isArray(row) || row.length !== PSI_COEFFICIENTS))
        fail(`encoding.multiple_psi needs multiple_max and log_psi: 3 rows of ${PSI_COEFFICIENTS} coefficients`);
      const muMin = finiteNumber(e.multiple_psi.mu_s_min, 'encoding.multiple_psi.mu_s_min');
      if (!(muMin >= -0.99 && muMin <= 0.5)) fail('encoding.multiple_psi.mu_s_min must be in [-0.99, 0.5]');
      const coefficient = (x) => (Math.abs(finiteNumber(x, 'log_psi')) <= 1e4 ? x : fail('log_psi must be numbers in [-1e4, 1e4]'));
      this.psi = { muMin: f(muMin), a: rows.map((row) => Float32Array.from(row, coefficient)) };
    }
    const outputs = factored ? 3 * this.terms.length + (this.multipleMax ? 3 : 0) : 4;
    // An aerosol family: the amount of one component is a fifth input, set at
    // run time (the `aerosol` property, a multiple of the atmosphere's).
    this.family = null;
    if (e.family !== undefined) {
      const range = e.family.aerosol_range;
      if (this.outputKind !== 'residual' || this.multipleMax || typeof e.family.component !== 'string' ||
          !Array.isArray(range) || range.length !== 2 || !(range[0] > 0) || !(range[1] > range[0]))
        fail('encoding.family needs residual outputs of single scattering, a component and aerosol_range [min, max]');
      const lo = Math.log(finiteNumber(range[0], 'aerosol_range')), hi = Math.log(finiteNumber(range[1], 'aerosol_range'));
      this.family = { component: e.family.component, min: range[0], max: range[1], a: f(2 / (hi - lo)), b: f(-(hi + lo) / (hi - lo)) };
    }
    this._aerosol = 1;
    const a = d.atmosphere ?? fail('no atmosphere');
    if (this.outputKind === 'residual') {
      // The march's atmosphere: its exponential components, and per term its component's scattering.
      const vec3 = (v, what) => (Array.isArray(v) && v.length === 3 ? v.map((x) => finiteNumber(x, what)) : fail(`${what} must be [r, g, b]`));
      this.ext = [];
      for (const c of a.components ?? fail('atmosphere.components is missing')) {
        if ((c.profile?.type ?? 'exponential') !== 'exponential') continue;
        const ext = { H: finiteNumber(c.profile?.scale_height_km ?? 8, 'scale_height_km'), beta: vec3(c.extinction_per_km, 'extinction_per_km'), name: c.name,
          family: this.family?.component === c.name };
        this.ext.push(ext);
        for (const t of this.terms)
          if (t.component === c.name) {
            t.ext = this.ext.length - 1;
            t.beta = vec3(c.scattering_per_km, 'scattering_per_km');
          }
      }
      if (this.ext.length > 4 || this.terms.some((t) => t.ext === undefined))
        fail('residual outputs need at most 4 exponential components, every scattering one among them');
      if (this.family && !this.terms.some((t) => t.component === this.family.component))
        fail(`the family's component '${this.family.component}' is not a scattering component`);
    }
    this.R0 = finiteNumber(a.planet_radius_km, 'atmosphere.planet_radius_km');
    this.Rtop = finiteNumber(a.top_radius_km, 'atmosphere.top_radius_km');
    const first = a.components?.[0];
    this.scaleHeight = first?.profile?.scale_height_km ?? 8;
    // Sub-networks: one shared with every output, or one per output.
    const shared = t.kind === 'shared';
    this.widths = [this.family ? 5 : 4, ...hidden, shared ? outputs : 1];
    const subnets = shared ? 1 : outputs;
    const w = d.weights;
    if (!Array.isArray(w) || w.length !== subnets) fail(`weights must hold ${subnets} sub-network(s)`);
    let params = 0;
    for (let l = 0; l + 1 < this.widths.length; ++l) params += this.widths[l + 1] * (this.widths[l] + 1);
    this.subnets = w.map((s) => {
      if (!Array.isArray(s) || s.length !== params) fail(`each sub-network has ${params} weights`);
      return Float32Array.from(s, (x) => finiteNumber(x, 'weights'));
    });
    this.outputs = outputs;
    this.topology = t.name ?? t.kind;
    this.weightCount = params * subnets;
    this.scaleAerosol();
  }

  // An aerosol family's amount, a multiple of its atmosphere's, within the
  // trained range; 1 (and only 1) for other networks.
  get aerosol() { return this._aerosol; }
  set aerosol(value) {
    const ok = this.family ? value >= this.family.min * (1 - 1e-9) && value <= this.family.max * (1 + 1e-9) : value === 1;
    if (!ok) fail(this.family ? `aerosol ${value} is outside the family's range [${this.family.min}, ${this.family.max}]`
      : 'aerosol: this network is not of an aerosol family');
    this._aerosol = value;
    this.scaleAerosol();
  }

  // The march's coefficients at the current aerosol amount (once per amount, not per sample).
  scaleAerosol() {
    if (this.outputKind !== 'residual') return;
    const k = f(this._aerosol);
    this.scaled = {
      ext: this.ext.map((e) => ({ ...e, beta: e.family ? e.beta.map((b) => f(f(b) * k)) : e.beta })),
      termBeta: this.terms.map((t) => (t.component === this.family?.component ? t.beta.map((b) => f(f(b) * k)) : t.beta)),
    };
  }

  // The network's inputs (mlp_hd.h's encode_inputs), with an aerosol family's fifth.
  encodeInputs(cosViewZenith, cosViewSun, cosSunZenith, density) {
    const four = this.encodeFour(cosViewZenith, cosViewSun, cosSunZenith, density);
    if (this.family) four.push(f(f(this.family.a * f(Math.log(f(this._aerosol)))) + this.family.b));
    return four;
  }

  encodeFour(cosViewZenith, cosViewSun, cosSunZenith, density) {
    const cz = f(cosViewZenith);
    if (this.inputs !== 'horizon') return [cz, f(cosViewSun), f(cosSunZenith), f(density)];
    const R0 = f(this.R0), top = f(f(this.Rtop) - R0), two = f(2 * R0);
    let h = f(-f(this.scaleHeight) * f(Math.log(f(density))));
    h = h > 0 ? (h < top ? h : top) : 0;
    const r = f(R0 + h);
    const rho = f(Math.sqrt(f(h * f(two + h))));
    const H = f(Math.sqrt(f(top * f(two + top))));
    const rc = f(r * cz);
    const arc = Math.abs(rc);
    let in0;
    if (cz < 0 && arc >= rho) {
      const disc = f(f(arc - rho) * f(arc + rho));
      const d = f(-rc - f(Math.sqrt(disc > 0 ? disc : 0)));
      const span = f(rho - h);
      const t = span > 0 ? f(f(d - h) / span) : 0;
      in0 = -f(f(HORIZON_GAP) + f(f(HORIZON_SPAN) * (t > 0 ? (t < 1 ? t : 1) : 0)));
    } else {
      const disc = f(f(rc * rc) + f(f(top - h) * f(f(two + top) + h)));
      const d = f(-rc + f(Math.sqrt(disc > 0 ? disc : 0)));
      const span = f(f(rho + H) - f(top - h));
      const t = span > 0 ? f(f(d - f(top - h)) / span) : 0;
      in0 = f(f(HORIZON_GAP) + f(f(HORIZON_SPAN) * (t > 0 ? (t < 1 ? t : 1) : 0)));
    }
    return [in0, f(cosViewSun), f(cosSunZenith), f(f(f(2 * rho) / H) - 1)];
  }

  // Residual outputs: the analytic single scattering per term and channel
  // (mlp_hd.h's analytic_terms), without the phase functions.
  // The observer and its view ray (mlp_hd.h's view_ray_precise): the
  // unclamped altitude hr, the altitude h clamped to the atmosphere, r, rho
  // and the ray's length d.
  viewRay(mu, density) {
    const R0 = f(this.R0), top = f(f(this.Rtop) - R0), two = f(2 * R0);
    const u = f(f(density - 1) / f(density + 1)), u2 = f(u * u);
    const ln = density > f(0.97) ? f(f(2 * u) * f(1 + f(u2 * f(f(0.333333343) + f(u2 * f(0.2)))))) : f(Math.log(density));
    const hr = f(-f(this.scaleHeight) * ln);
    const h = hr > 0 ? (hr < top ? hr : top) : 0;
    const r = f(R0 + h);
    const rho = f(Math.sqrt(f(h * f(two + h))));
    const rc = f(r * mu), arc = Math.abs(rc);
    let d;
    if (mu < 0 && arc >= rho) {
      const disc = f(f(arc - rho) * f(arc + rho));
      d = f(f(rho * rho) / f(arc + f(Math.sqrt(disc > 0 ? disc : 0))));
    } else {
      const k = f(f(top - h) * f(f(two + top) + h));
      const disc = f(f(rc * rc) + k);
      const s = f(Math.sqrt(disc > 0 ? disc : 0));
      d = rc > 0 ? f(k / f(rc + s)) : f(-rc + s);
    }
    return { hr, h, r, rho, d };
  }

  // An observer above the top (the inputs see it at the top) whose ray misses
  // the atmosphere sees no air (mlp_hd.h's misses_atmosphere).
  missesAtmosphere(mu, hr) {
    const R0 = f(this.R0), top = f(f(this.Rtop) - R0);
    const r = f(R0 + hr), rt = f(R0 + top), s2 = f(f(1 - mu) * f(1 + mu));
    return hr > top && (mu >= 0 || f(f(r * r) * s2) >= f(rt * rt));
  }

  analyticTerms(mu, nu, muS, density) {
    const R0 = f(this.R0);
    const base = new Float32Array(3 * this.terms.length);
    const { hr, h, r, rho, d } = this.viewRay(mu, density);
    if (this.missesAtmosphere(mu, hr)) return base;
    // The planet's shadow on the ray (shadow_span).
    let lo = 0, hi = d, shadow = true;
    const c = f(r * muS);
    if (nu > 0) { const t = f(-c / nu); hi = hi < t ? hi : t; }
    else if (nu < 0) { const t = f(-c / nu); lo = lo > t ? lo : t; }
    else shadow = c < 0;
    const A = f(f(1 - nu) * f(1 + nu)), B = f(f(2 * r) * f(mu - f(muS * nu))), C = f(f(rho - c) * f(rho + c));
    if (A <= f(1e-12)) {
      if (B > 0) { const t = f(-C / B); hi = hi < t ? hi : t; }
      else if (B < 0) { const t = f(-C / B); lo = lo > t ? lo : t; }
      else shadow = shadow && C < 0;
    } else {
      const D = f(f(B * B) - f(f(4 * A) * C));
      if (D > 0) {
        const sq = f(Math.sqrt(D));
        const q = f(-0.5 * f(B + (B < 0 ? -sq : sq)));
        const ta = f(q / A), tb = q !== 0 ? f(C / q) : -ta;
        const t0 = ta < tb ? ta : tb, t1 = ta < tb ? tb : ta;
        lo = lo > t0 ? lo : t0;
        hi = hi < t1 ? hi : t1;
      } else shadow = false;
    }
    shadow = shadow && lo < hi;
    const rho2 = f(rho * rho), twoRMu = f(f(2 * r) * mu);
    const altitude = (t) => {
      let q = f(rho2 + f(t * f(twoRMu + t)));
      q = q > 0 ? q : 0;
      return f(q / f(f(Math.sqrt(f(q + f(R0 * R0)))) + R0));
    };
    // An aerosol family scales its component's coefficients; its march takes the
    // view's depth as Chapman integrals from the observer (mlp_hd.h).
    const { ext, termBeta } = this.scaled;
    const prev = ext.map((e) => f(Math.exp(f(-h / f(e.H)))));
    const obs = prev.slice();
    const tau = [0, 0, 0];
    let tPrev = 0;
    for (let part = 0; part < 2; ++part) {
      const a = part === 0 ? 0 : (shadow ? hi : d);
      const b = part === 0 ? (shadow ? lo : d) : d;
      if (!(b > a)) continue;
      const dt = f(f(b - a) * f(1 / RESIDUAL_STEPS));
      let tLow = f(-r * mu);
      tLow = tLow < a ? a : (tLow > b ? b : tLow);
      const hEnd = [altitude(a), altitude(b), altitude(tLow)];
      const cEnd = [f(f(f(r * mu) + a) / f(R0 + hEnd[0])), f(f(f(r * mu) + b) / f(R0 + hEnd[1]))];
      const sumRho = ext.map(() => 0);
      const partSum = new Float32Array(base.length);
      let fk = 0.5;
      for (let k = 0; k < RESIDUAL_STEPS; ++k) {
        const t = f(a + f(fk * dt));
        fk = f(fk + 1);
        const hp = altitude(t);
        const rp = f(R0 + hp);
        const cosChi = f(f(f(r * muS) + f(t * nu)) / rp);
        const sun = [0, 0, 0];
        if (this.family) tau.fill(0);
        const dens = ext.map((e, i) => {
          const H = f(e.H);
          const rhoP = f(Math.exp(f(-hp / H)));
          sumRho[i] = f(sumRho[i] + f(rhoP * dt));
          const view = this.family ? chapmanSegment(R0, H, h, mu, obs[i], hp, f(f(f(r * mu) + t) / rp), rhoP)
            : f(f(0.5 * f(rhoP + prev[i])) * f(t - tPrev));
          const depth = chapmanDepth(hp, R0, H, cosChi, rhoP);
          for (let ch = 0; ch < 3; ++ch) {
            tau[ch] = f(tau[ch] + f(f(e.beta[ch]) * view));
            sun[ch] = f(sun[ch] + f(f(e.beta[ch]) * depth));
          }
          prev[i] = rhoP;
          return rhoP;
        });
        tPrev = t;
        for (let ch = 0; ch < 3; ++ch) {
          const tr = f(f(Math.exp(f(-f(tau[ch] + sun[ch])))) * dt);
          this.terms.forEach((term, k2) => {
            partSum[3 * k2 + ch] = f(partSum[3 * k2 + ch] + f(f(f(termBeta[k2][ch]) * dens[term.ext]) * tr));
          });
        }
      }
      this.terms.forEach((term, k2) => {
        const H = f(ext[term.ext].H);
        const exact = chapmanSegment(R0, H, hEnd[0], cEnd[0], f(Math.exp(f(-hEnd[0] / H))), hEnd[1], cEnd[1],
          f(Math.exp(f(-hEnd[1] / H))));
        const g = f(f(f(hEnd[0] + hEnd[1]) - f(2 * hEnd[2])) / H);
        let w = f(f(g - 0.5) * 0.5);
        w = w > 0 ? (w < 1 ? w : 1) : 0;
        w = f(f(w * w) * f(3 - f(2 * w)));
        const s = sumRho[term.ext];
        const ratio = s > 0 && exact > 0 ? f(exact / s) : 1;
        const scale = f(1 + f(w * f(ratio - 1)));
        for (let ch = 0; ch < 3; ++ch) base[3 * k2 + ch] = f(base[3 * k2 + ch] + f(scale * partSum[3 * k2 + ch]));
      });
    }
    return base;
  }

  // Residual outputs' multiple-scattering term, marched: the isotropic march of
  // the sky's mean radiance psi per channel (mlp_hd.h's analytic_multiple).
  analyticMultiple(mu, nu, muS, density) {
    const R0 = f(this.R0), top = f(f(this.Rtop) - R0);
    const out = [0, 0, 0];
    const { hr, h, r, rho, d } = this.viewRay(mu, density);
    if (this.missesAtmosphere(mu, hr)) return out;
    const rho2 = f(rho * rho), twoRMu = f(f(2 * r) * mu);
    const altitude = (t) => {
      let q = f(rho2 + f(t * f(twoRMu + t)));
      q = q > 0 ? q : 0;
      return f(q / f(f(Math.sqrt(f(q + f(R0 * R0)))) + R0));
    };
    const dt = f(d * f(1 / MULTIPLE_STEPS));
    const prev = this.ext.map((e) => f(Math.exp(f(-h / f(e.H)))));
    const tau = [0, 0, 0];
    const { muMin, a } = this.psi;
    const row = PSI_SUN_DEGREE + 1;
    for (let k = 0; k < MULTIPLE_STEPS; ++k) {
      const tm = f(f(k + 0.5) * dt), te = f(f(k + 1) * dt);
      const hm = altitude(tm), he = altitude(te);
      const mus = f(f(f(r * muS) + f(tm * nu)) / f(R0 + hm));
      const mid = this.ext.map((e) => f(Math.exp(f(-hm / f(e.H)))));
      const end = this.ext.map((e) => f(Math.exp(f(-he / f(e.H)))));
      let px = f(f(f(2 * hm) / top) - 1);
      let py = f(f(f(f(2 * mus) - 1) - muMin) / f(1 - muMin));
      px = px > -1 ? (px < 1 ? px : 1) : -1;
      py = py > -1 ? (py < 1 ? py : 1) : -1;
      for (let ch = 0; ch < 3; ++ch) {
        let dtau = 0, sca = 0;
        this.ext.forEach((e, i) => { dtau = f(dtau + f(f(f(f(e.beta[ch]) * 0.5) * f(prev[i] + end[i])) * dt)); });
        this.terms.forEach((t) => { sca = f(sca + f(f(t.beta[ch]) * mid[t.ext])); });
        const fac = dtau > f(0.1) ? f(f(1 - f(Math.exp(-dtau))) / dtau)
          : f(1 - f(dtau * f(0.5 - f(dtau * f(f(0.166666672) - f(dtau * f(0.0416666679)))))));
        const w = f(f(f(f(Math.exp(-tau[ch])) * sca) * dt) * fac);
        tau[ch] = f(tau[ch] + dtau);
        let acc = 0;
        for (let i = PSI_ALTITUDE_DEGREE; i >= 0; --i) {
          let v = 0;
          for (let j = PSI_SUN_DEGREE; j >= 0; --j) v = f(f(v * py) + a[ch][i * row + j]);
          acc = f(f(acc * px) + v);
        }
        out[ch] = f(out[ch] + f(w * f(Math.exp(acc))));
      }
      for (let i = 0; i < prev.length; ++i) prev[i] = end[i];
    }
    return out;
  }

  // The encoded outputs for the four inputs.
  forward(inputs) {
    const enc = new Float32Array(this.outputs);
    this.subnets.forEach((w, s) => {
      let a = inputs;
      let offset = 0;
      for (let l = 0; l + 1 < this.widths.length; ++l) {
        const nIn = this.widths[l];
        const nOut = this.widths[l + 1];
        const z = new Float32Array(nOut);
        const b = offset + nOut * nIn;
        for (let r = 0; r < nOut; ++r) {
          let sum = 0;
          for (let c = 0; c < nIn; ++c) sum = f(sum + f(w[offset + r * nIn + c] * a[c]));
          z[r] = activation(f(sum + w[b + r]));
        }
        a = z;
        offset = b + nOut;
      }
      if (this.subnets.length === 1) enc.set(a);
      else enc[s] = a[0];
    });
    return enc;
  }

  // Radiance per unit sun irradiance (1/sr), linear RGB, as [r, g, b]:
  // cosViewZenith = V·U, cosViewSun = V·L, cosSunZenith = U·L (V the view
  // direction, U the local vertical at the observer, L towards the sun) and
  // density the relative density of the first component at the observer, in (0, 1].
  radiance(cosViewZenith, cosViewSun, cosSunZenith, density) {
    const enc = this.forward(this.encodeInputs(cosViewZenith, cosViewSun, cosSunZenith, density));
    if (this.outputKind === 'residual') {
      const base = this.analyticTerms(f(cosViewZenith), f(cosViewSun), f(cosSunZenith), f(density));
      const c = [0, 0, 0];
      this.terms.forEach((t, k) => {
        const p = t.phase(f(t.g), f(cosViewSun));
        for (let ch = 0; ch < 3; ++ch)
          c[ch] = f(c[ch] + f(f(p * base[3 * k + ch]) * f(Math.exp(f(RESIDUAL_SCALE * f(enc[3 * k + ch] - 0.5))))));
      });
      if (this.psi) {
        const at = 3 * this.terms.length;
        const m = this.analyticMultiple(f(cosViewZenith), f(cosViewSun), f(cosSunZenith), f(density));
        for (let ch = 0; ch < 3; ++ch)
          c[ch] = f(c[ch] + f(m[ch] * f(Math.exp(f(RESIDUAL_SCALE * f(enc[at + ch] - 0.5))))));
      } else if (this.multipleMax) {
        const at = 3 * this.terms.length;
        for (let ch = 0; ch < 3; ++ch) c[ch] = f(c[ch] + decodeLog(enc[at + ch], f(this.multipleMax[ch]), MULTIPLE_LOG_RANGE));
      }
      return c;
    }
    if (this.outputKind === 'phase-factored') {
      const c = [0, 0, 0];
      this.terms.forEach((t, k) => {
        const p = t.phase(f(t.g), f(cosViewSun));
        for (let ch = 0; ch < 3; ++ch) c[ch] = f(c[ch] + f(p * decodeLog(enc[3 * k + ch], f(t.max[ch]), f(this.logRange))));
      });
      return c;
    }
    const m = f(f(enc[3] - f(ENCODE_OFFSET)) * INV_SCALE);
    if (!(m > 0)) return [0, 0, 0];
    const maxN = f(this.maxN), logRange = f(this.logRange);
    const n = this.brightness === 'linear' ? f(m * maxN) : f(maxN * f(Math.exp(f(logRange * f(m - 1)))));
    return [f(decodeUnit(enc[0]) * n), f(decodeUnit(enc[1]) * n), f(decodeUnit(enc[2]) * n)];
  }
}
