// NeuralSky (three.js) in headless Chromium, WebGL 2 on SwiftShader: the
// sky drawn by `skybake sky export --format glsl-es` matches the JavaScript
// forward pass of the same weights file per pixel, with no console error.
// Needs SKYBAKE_CLI, SKYBAKE_TEST_DATA and a Chromium (SKYBAKE_CHROMIUM, else
// /usr/bin/chromium); exits 77 (skipped) without one.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const chromium = process.env.SKYBAKE_CHROMIUM ?? '/usr/bin/chromium';
if (!existsSync(chromium)) {
  console.log(`skipped: no Chromium at ${chromium}`);
  process.exit(77);
}
const { build } = await import('esbuild');
const puppeteer = (await import('puppeteer-core')).default;

export async function openPage(url, onConsole) {
  const browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
  });
  const page = await browser.newPage();
  page.on('console', (m) => onConsole(m.type(), m.text()));
  page.on('pageerror', (e) => onConsole('error', String(e)));
  await page.goto(url);
  return { browser, page };
}

test('NeuralSky draws the network of the weights file, and skybakeLighting lights baked data with its SH light', async () => {
  const dir = mkdtempSync(join(tmpdir(), 'skybake-web-'));
  const networks = [];
  for (const name of ['v3_earth_default.json', 'v1_paper.json', 'v1_shared_linear.json', 'v3_earth_residual.json',
    'v3_earth_multiple.json', 'v3_earth_multiple_march.json']) {
    const weightsFile = join(process.env.SKYBAKE_TEST_DATA, 'neural', name);
    const glslFile = join(dir, `${name}.glsl`);
    execFileSync(process.env.SKYBAKE_CLI, ['sky', 'export', weightsFile, '--format', 'glsl-es', '-o', glslFile], { stdio: 'ignore' });
    networks.push(`{ name: ${JSON.stringify(name)}, weights: ${readFileSync(weightsFile, 'utf8')}, glsl: ${JSON.stringify(readFileSync(glslFile, 'utf8'))} }`);
  }
  execFileSync(process.env.SKYBAKE_CLI, ['prt', 'export', '--order', '3', '--channels', '1', '--format', 'glsl-es', '-o', join(dir, 'prt.glsl')], { stdio: 'ignore' });
  writeFileSync(join(dir, 'fixture.js'), `export const networks = [${networks.join(',\n')}];\n` +
    `export const prtGlsl = ${JSON.stringify(readFileSync(join(dir, 'prt.glsl'), 'utf8'))};\n`);
  await build({
    entryPoints: [join(here, 'browser', 'sky_page.js')],
    bundle: true,
    format: 'iife',
    outfile: join(dir, 'page.js'),
    logLevel: 'error',
    plugins: [{ name: 'fixture', setup(b) { b.onResolve({ filter: /fixture\.js$/ }, () => ({ path: join(dir, 'fixture.js') })); } }],
  });
  writeFileSync(join(dir, 'index.html'), '<!doctype html><meta charset="utf-8"><body><script src="page.js"></script></body>\n');
  const errors = [];
  const { browser, page } = await openPage(pathToFileURL(join(dir, 'index.html')).href, (type, text) => {
    if (type === 'error') errors.push(text);
  });
  try {
    await page.waitForFunction('window.skybakeResult !== undefined', { timeout: 60000 });
    const results = await page.evaluate('window.skybakeResult');
    assert.ok(Array.isArray(results), results?.error);
    assert.deepEqual(errors, []);
    const lit = await page.evaluate('window.skybakeLighting');
    for (const [mode, r] of Object.entries(lit)) {
      console.log(`skybakeLighting '${mode}': ${r.got.map((v) => v.toPrecision(6))} against ${r.want.map((v) => v.toPrecision(6))}`);
      assert.ok(r.rel < (mode === 'prt' ? 1e-5 : 2e-4), `${mode}: relative difference ${r.rel}`);
    }
    assert.deepEqual(Object.keys(lit), ['prt', 'ao', 'ao-texture']);
    for (const r of results) {
      console.log(`${r.name}: ${r.compared} channel values, max relative difference ${r.maxRel.toExponential(2)} from the JS forward pass; ` +
        `view directions within ${r.dirMaxErr.toExponential(1)} of the pixel centres' rays; exp2 within ${r.exp2MaxRel.toExponential(1)}`);
      assert.equal(r.webgl2, true);
      assert.ok(r.compared > 2000, `only ${r.compared} values compared`);
      // The JS pass rounds as the library does; the GPU may contract
      // multiply-adds, and log decoding multiplies an ulp by about 15 (as in
      // neural_sky.test.mjs against the CLI).
      assert.ok(r.maxRel < 3e-5, `${r.name}: max relative difference ${r.maxRel}`);
      assert.ok(r.dirMaxErr < 5e-3, `${r.name}: view directions off by ${r.dirMaxErr}`);
    }
  } finally {
    await browser.close();
  }
});
