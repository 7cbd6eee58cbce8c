// `skybake web` end to end, in headless Chromium (WebGL 2 on SwiftShader):
// sites of a PRT bake and of an AO bake open from file:// (and the first from
// --serve) with no console error and draw a lit model under a sky; bad inputs fail in the CLI with
// one line; a page without its data, or a browser without WebGL 2, says so
// on the page. Needs SKYBAKE_CLI, SKYBAKE_TEST_DATA and SKYBAKE_CHROMIUM.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { createServer } from 'node:net';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { pathToFileURL } from 'node:url';

const chromium = process.env.SKYBAKE_CHROMIUM ?? '/usr/bin/chromium';
const cli = process.env.SKYBAKE_CLI;
const weights = join(process.env.SKYBAKE_TEST_DATA, 'neural', 'v3_earth_default.json');
const puppeteer = (await import('puppeteer-core')).default;
const dir = mkdtempSync(join(tmpdir(), 'skybake-site-'));

function skybake(...args) {
  const r = spawnSync(cli, args, { encoding: 'utf8' });
  return { code: r.status, out: r.stdout, err: r.stderr };
}

async function open(url, extraArgs = []) {
  const browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--window-size=640,400', ...extraArgs],
  });
  const page = await browser.newPage();
  await page.setViewport({ width: 640, height: 400 });
  const errors = [];
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(url);
  return { browser, page, errors };
}

// The page at `url` fails with a message matching `want`, on the page and in
// the console, rather than a blank canvas.
async function expectPageError(url, want, extraArgs = []) {
  const { browser, page, errors } = await open(url, extraArgs);
  try {
    await page.waitForFunction('window.skybakeSite?.error', { timeout: 60000 });
    const text = await page.evaluate(() => document.getElementById('message').textContent);
    assert.match(text, want);
    assert.ok(errors.some((e) => want.test(e)), `the console says it too: ${errors}`);
  } finally {
    await browser.close();
  }
}

// Mean RGB (0–255) of the view over a rectangle in fractions of its size.
const regionMean = (page, ...r) => page.evaluate((r) => window.skybakeSite.regionMean(...r), r);

test('skybake web: PRT and AO sites, and their errors', async () => {
  const city = join(dir, 'city.glb');
  assert.equal(skybake('mesh', 'generate', '--kind', 'city', '--triangles', '3000', '--seed', '2', '-o', city).code, 0);
  assert.equal(skybake('prt', 'bake', city, '--order', '3', '--rule', 'lebedev:194', '-o', join(dir, 'city_prt.glb')).code, 0);
  assert.equal(skybake('ao', city, '--rule', 'lebedev:194', '-o', join(dir, 'city_ao.glb')).code, 0);

  const port = await new Promise((resolve) => {
    const server = createServer().listen(0, '127.0.0.1', () => {
      const p = server.address().port;
      server.close(() => resolve(p));
    });
  });
  for (const [name, shading, serve] of [['city_prt', 'PRT', false], ['city_ao', 'AO', false], ['city_prt', 'PRT', true]]) {
    const site = join(dir, `site_${name}${serve ? '_served' : ''}`);
    let url = `${pathToFileURL(join(site, 'index.html')).href}?elevation=20&azimuth=135`;
    let server = null;
    if (serve) {
      server = spawn(cli, ['web', join(dir, `${name}.glb`), '--model', weights, '-o', site, '--serve', '--port', String(port)]);
      let out = '';
      server.stdout.on('data', (d) => (out += d));
      for (let i = 0; i < 200 && !/serving .* at http:\/\/127\.0\.0\.1:\d+\//.test(out); ++i) await new Promise((r) => setTimeout(r, 100));
      assert.match(out, /serving .* at http:\/\/127\.0\.0\.1:\d+\//);
      url = `http://127.0.0.1:${port}/index.html?elevation=20&azimuth=135`;
      for (let i = 0; i < 100; ++i) {
        try {
          if ((await fetch(url)).ok) break;
        } catch {}
        await new Promise((r) => setTimeout(r, 100));
      }
    } else {
      const r = skybake('web', join(dir, `${name}.glb`), '--model', weights, '-o', site);
      assert.equal(r.code, 0, r.err);
      assert.match(r.out + r.err, new RegExp(`${shading} shading`));
    }
    for (const f of ['index.html', 'skybake-site.js', 'data.js']) assert.ok(existsSync(join(site, f)), f);
    const { browser, page, errors } = await open(url);
    try {
      await page.waitForFunction('(window.skybakeSiteFrames ?? 0) >= 3 || window.skybakeSite?.error', { timeout: 120000 });
      const s = await page.evaluate('({ error: window.skybakeSite.error, shading: window.skybakeSite.shading })');
      assert.equal(s.error, undefined, s.error);
      assert.equal(s.shading, shading);
      assert.deepEqual(errors, []);
      const sky = await regionMean(page, 0.0, 0.0, 1.0, 0.08);
      const model = await regionMean(page, 0.4, 0.45, 0.6, 0.65);
      console.log(`${name}${serve ? ' (served)' : ''}: sky ${sky.map((v) => v.toFixed(0))}, model ${model.map((v) => v.toFixed(0))}`);
      // A daytime sky: bright and blue; the model lit, and not the sky.
      assert.ok(sky[2] > 40 && sky[2] > 1.2 * sky[0], `sky ${sky}`);
      assert.ok(Math.max(...model) > 25, `model ${model}`);
      assert.ok(Math.abs(model[2] - sky[2]) > 5 || Math.abs(model[0] - sky[0]) > 5, 'the model is not drawn');
      if (name === 'city_prt' && !serve) {
        // The panel: AO shading of the same bake (its COLOR_0) differs from
        // PRT's and is lit too; a shift-drag moves the sun down.
        await page.select('#shading', 'AO');
        const ao = await regionMean(page, 0.4, 0.45, 0.6, 0.65);
        console.log(`city_prt as AO: model ${ao.map((v) => v.toFixed(0))}`);
        assert.ok(Math.max(...ao) > 25 && Math.abs(ao[0] - model[0]) + Math.abs(ao[2] - model[2]) > 0.5, `AO ${ao} against PRT ${model}`);
        await page.keyboard.down('Shift');
        await page.mouse.move(320, 300);
        await page.mouse.down();
        await page.mouse.move(360, 340, { steps: 4 });
        await page.mouse.up();
        await page.keyboard.up('Shift');
        const elevation = await page.evaluate(() => Number(document.getElementById('elevation').value));
        assert.ok(elevation < 15, `the sun is at ${elevation}° after the drag`);
        assert.deepEqual(errors, []);
      }
    } finally {
      await browser.close();
      if (server) server.kill();
    }
  }

  // Bad inputs: one line on stderr, a non-zero exit, no site.
  const corrupt = join(dir, 'corrupt.json');
  writeFileSync(corrupt, '{"format": "skybake-neural-sky", "weights": [');
  writeFileSync(join(dir, 'garbage.glb'), 'glTF, or not at all');
  for (const [args, code] of [
    [[join(dir, 'city_prt.glb'), '--model', corrupt, '-o', join(dir, 'bad1')], 1],
    [[join(dir, 'city.ply'), '--model', weights, '-o', join(dir, 'bad2')], 2],
    [[join(dir, 'missing.glb'), '--model', weights, '-o', join(dir, 'bad3')], 1],
    [[join(dir, 'garbage.glb'), '--model', weights, '-o', join(dir, 'bad4')], 1],
  ]) {
    const r = skybake('web', ...args);
    assert.equal(r.code, code, r.err);
    assert.equal(r.err.trim().split('\n').length, 1, r.err);
    assert.ok(!existsSync(args[4]), `${args[4]} was left behind`);
  }

  // A page whose data.js is gone, and a browser without WebGL 2: a message, not a blank page.
  const site = join(dir, 'site_city_ao');
  rmSync(join(site, 'data.js'));
  for (const [extra, want] of [[[], /data\.js/], [['--disable-3d-apis'], /WebGL 2/]]) {
    if (extra.length) skybake('web', join(dir, 'city_ao.glb'), '--model', weights, '-o', site);
    await expectPageError(pathToFileURL(join(site, 'index.html')).href, want, extra);
  }
});

// The page against `skybake view --screenshot` of the same model, camera,
// sun and exposure (one sample per pixel on both sides, no ground: the viewer
// draws none), at noon, sunset and twilight, and with the DPRT glossy layer:
// PSNR of the 8-bit images.
test('skybake web matches skybake view (PSNR ≥ 30 dB at three suns)', async () => {
  const engine = join(process.env.SKYBAKE_ASSIMP_MODELS || '/usr/share/assimp/models', 'glTF2', '2CylinderEngine-glTF-Binary', '2CylinderEngine.glb');
  const baked = join(dir, 'engine_prt.glb');
  let r = skybake('prt', 'bake', engine, '--order', '3', '--rule', 'lebedev:194', '-o', baked);
  assert.equal(r.code, 0, r.err);
  const site = join(dir, 'site_engine');
  r = skybake('web', baked, '--model', weights, '-o', site);
  assert.equal(r.code, 0, r.err);
  const [W, H, view] = [960, 540, '20,8'];
  const { browser, page, errors } = await open('about:blank', [`--window-size=${W},${H}`]);
  await page.setViewport({ width: W, height: H });
  const means = {}; // name: [viewer, page] mean 8-bit value
  try {
    const suns = [['noon', 60, 60, 2, 'prt'], ['sunset', 3, 60, 4.5, 'prt'], ['twilight', -4, 60, 10, 'prt'], ['sunset, PRT + glossy', 3, 60, 4.5, 'dprt']];
    for (const [name, elevation, azimuth, ev, shading] of suns) {
      const png = join(dir, `view_${name.replace(/\W+/g, '_')}.png`);
      r = skybake('view', baked, '--screenshot', png, '--model', weights, '--size', `${W}x${H}`, '--sun-elevation-deg', String(elevation),
        '--sun-azimuth-deg', String(azimuth), '--set', `view=${view}`, '--set', `exposure=${ev}`, '--set', 'samples=1', '--set', `shading=${shading}`);
      assert.equal(r.code, 0, r.err);
      await page.goto(`${pathToFileURL(join(site, 'index.html')).href}?elevation=${elevation}&azimuth=${azimuth}&view=${view}&exposure=${ev}&shading=${shading}&ground=off&aa=off`);
      await page.waitForFunction('(window.skybakeSiteFrames ?? 0) >= 2 || window.skybakeSite?.error', { timeout: 120000 });
      assert.equal(await page.evaluate('window.skybakeSite.error'), undefined);
      const reference = `data:image/png;base64,${readFileSync(png).toString('base64')}`;
      const { psnr, width, height, mean, meanGot } = await page.evaluate(async (url) => {
        const img = new Image();
        img.src = url;
        await img.decode();
        const c = document.createElement('canvas');
        [c.width, c.height] = [img.width, img.height];
        const ctx = c.getContext('2d');
        ctx.drawImage(img, 0, 0);
        const ref = ctx.getImageData(0, 0, img.width, img.height).data;
        const got = window.skybakeSite.pixels();
        let se = 0, sum = 0, sumGot = 0;
        for (let i = 0; i < ref.length; i += 4)
          for (let k = 0; k < 3; ++k) {
            se += (got[i + k] - ref[i + k]) ** 2;
            sum += ref[i + k];
            sumGot += got[i + k];
          }
        const n = (ref.length / 4) * 3;
        return { psnr: 10 * Math.log10((255 * 255 * n) / Math.max(se, 1e-9)), width: img.width, height: img.height, mean: sum / n, meanGot: sumGot / n };
      }, reference);
      means[name] = [mean, meanGot];
      console.log(`${name} (sun ${elevation}°, ${ev} EV): PSNR ${psnr.toFixed(2)} dB against skybake view (mean ${mean.toFixed(1)} of 255)`);
      assert.deepEqual([width, height], [W, H]);
      assert.ok(mean > 8, `the viewer's image is too dark to compare (${mean})`);
      assert.ok(psnr >= 30, `${name}: ${psnr.toFixed(2)} dB`);
    }
    // The glossy layer is there on both sides, and adds as much light.
    const viewerGlossy = means['sunset, PRT + glossy'][0] - means.sunset[0], pageGlossy = means['sunset, PRT + glossy'][1] - means.sunset[1];
    console.log(`the glossy layer adds ${viewerGlossy.toFixed(3)} (viewer) and ${pageGlossy.toFixed(3)} (page) to the mean`);
    assert.ok(viewerGlossy > 0.2, `viewer ${viewerGlossy}`);
    assert.ok(Math.abs(pageGlossy / viewerGlossy - 1) < 0.25, `page ${pageGlossy} against viewer ${viewerGlossy}`);
    assert.deepEqual(errors, []);
  } finally {
    await browser.close();
  }
});

// A .glb whose JSON chunk `edit` changed (the BIN chunk kept).
function editGlb(input, output, edit) {
  const b = readFileSync(input);
  const jsonLength = b.readUInt32LE(12);
  const doc = JSON.parse(b.subarray(20, 20 + jsonLength).toString('utf8'));
  edit(doc);
  let text = JSON.stringify(doc);
  while (text.length % 4) text += ' ';
  const json = Buffer.from(text, 'utf8'), rest = b.subarray(20 + jsonLength);
  const head = Buffer.alloc(20);
  head.writeUInt32LE(0x46546c67, 0);
  head.writeUInt32LE(2, 4);
  head.writeUInt32LE(20 + json.length + rest.length, 8);
  head.writeUInt32LE(json.length, 12);
  head.writeUInt32LE(0x4e4f534a, 16);
  writeFileSync(output, Buffer.concat([head, json, rest]));
}

// AO that only an occlusion texture carries (as other tools write it): the
// page lights the model through it; without UVs to read it, the page says so.
// Blender's Suzanne with `skybake ao --texture`, her _AO and COLOR_0 removed.
test('skybake web reads AO from an occlusion texture, and says when there are no UVs', async (t) => {
  const suzanne = join(dir, 'suzanne.glb');
  const made = spawnSync('blender', ['-b', '--factory-startup', '--python', join(process.env.SKYBAKE_TEST_DATA, 'blender', 'make_suzanne.py'), '--', suzanne, 'material']);
  if (made.status !== 0) return t.skip('no blender (scripts/install-deps.sh installs it)');
  const baked = join(dir, 'suzanne_ao.glb');
  assert.equal(skybake('ao', suzanne, '--rule', 'lebedev:86', '--texture', '64', '-o', baked).code, 0);
  const drop = (names) => (doc) => doc.meshes.forEach((m) => m.primitives.forEach((p) => names.forEach((n) => delete p.attributes[n])));
  editGlb(baked, join(dir, 'suzanne_tex.glb'), drop(['_AO', 'COLOR_0']));
  editGlb(baked, join(dir, 'suzanne_nouv.glb'), drop(['_AO', 'COLOR_0', 'TEXCOORD_0']));
  for (const [name, shading, message] of [['suzanne_tex', 'AO', null], ['suzanne_nouv', 'sun', /occlusion texture but no UVs/]]) {
    const site = join(dir, `site_${name}`);
    const r = skybake('web', join(dir, `${name}.glb`), '--model', weights, '-o', site);
    assert.equal(r.code, 0, r.err);
    assert.match(r.out + r.err, new RegExp(`\\(${shading === 'sun' ? 'sun only' : shading} shading`)); // the command names what the page uses
    const { browser, page, errors } = await open(`${pathToFileURL(join(site, 'index.html')).href}?elevation=30&azimuth=40`);
    try {
      await page.waitForFunction('(window.skybakeSiteFrames ?? 0) >= 3 || window.skybakeSite?.error', { timeout: 120000 });
      assert.equal(await page.evaluate('window.skybakeSite.error'), undefined);
      assert.equal(await page.evaluate('window.skybakeSite.shading'), shading);
      const model = await regionMean(page, 0.4, 0.4, 0.6, 0.6);
      console.log(`${name}: ${shading} shading, model ${model.map((v) => v.toFixed(0))}`);
      assert.ok(Math.max(...model) > 25, `model ${model}`);
      const text = await page.evaluate(() => document.getElementById('message').textContent);
      if (message) {
        assert.match(text, message);
        assert.ok(errors.some((e) => message.test(e)), `the console says it too: ${errors}`);
      } else {
        assert.equal(text, '');
        assert.deepEqual(errors, []);
      }
    } finally {
      await browser.close();
    }
  }
});

// A URL setting out of range, or a shading the model has no data for: one
// message on the page and in the console, not a blank canvas.
test('skybake web: a bad URL setting is a message on the page', async () => {
  const city = join(dir, 'city_url.glb'), baked = join(dir, 'city_url_ao.glb'), site = join(dir, 'site_url');
  assert.equal(skybake('mesh', 'generate', '--kind', 'city', '--triangles', '500', '--seed', '1', '-o', city).code, 0);
  assert.equal(skybake('ao', city, '--rule', 'lebedev:50', '-o', baked).code, 0);
  assert.equal(skybake('web', baked, '--model', weights, '-o', site).code, 0);
  for (const [query, want] of [['elevation=95', /elevation=95 is not a number in \[-20, 90\]/], ['view=10', /view=10 is not AZIMUTH,ELEVATION/],
    ['shading=prt', /shading=prt: this model has no data for it/], ['shading=glossy', /shading=glossy is not prt, dprt, ao or sun/]]) {
    await expectPageError(`${pathToFileURL(join(site, 'index.html')).href}?${query}`, want);
  }
});
