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
    if (!['radiance', 'phase-factored'].includes(this.outputKind)) fail(`encoding.outputs '${this.outputKind}' is unknown`);
    if (!['log', 'linear'].includes(this.brightness)) fail(`encoding.brightness '${this.brightness}' is unknown`);
    this.maxN = finiteNumber(e.max_n, 'encoding.max_n');
    this.logRange = finiteNumber(e.log_range, 'encoding.log_range');
    this.terms = [];
    if (this.outputKind === 'phase-factored') {
      for (const term of e.terms ?? fail('encoding.terms is missing')) {
        const phase = PHASES[term.phase] ?? fail(`phase '${term.phase}' is unknown`);
        this.terms.push({ phase, g: finiteNumber(term.g ?? 0, 'terms.g'), max: term.max_s.map((m) => finiteNumber(m, 'terms.max_s')) });
      }
    }
    const outputs = this.outputKind === 'phase-factored' ? 3 * this.terms.length : 4;
    const a = d.atmosphere ?? fail('no atmosphere');
    this.R0 = finiteNumber(a.planet_radius_km, 'atmosphere.planet_radius_km');
    this.Rtop = finiteNumber(a.top_radius_km, 'atmosphere.top_radius_km');
    const first = a.components?.[0];
    this.scaleHeight = first?.profile?.scale_height_km ?? 8;
    // Sub-networks: one shared with every output, or one per output.
    const shared = t.kind === 'shared';
    this.widths = [4, ...hidden, shared ? outputs : 1];
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
  }

  // The network's four inputs (mlp_hd.h's encode_inputs).
  encodeInputs(cosViewZenith, cosViewSun, cosSunZenith, density) {
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
