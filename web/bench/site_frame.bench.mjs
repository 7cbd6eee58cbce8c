// Frame time of a `skybake web` site in headless Chromium (WebGL 2 on
// SwiftShader), PRT shading with the network behind the model (and PRT +
// glossy, and the sun alone) against its baseline in the same page run: the
// same model drawn flat in one colour ('flat': no light, no shadow map, the
// same network background), measured first and last.
//   node web/bench/site_frame.bench.mjs SITE/index.html [WIDTHxHEIGHT] [seconds]
import { pathToFileURL } from 'node:url';
import { resolve } from 'node:path';
import puppeteer from 'puppeteer-core';

const [site, size = '1920x1080', seconds = '8'] = process.argv.slice(2);
if (!site) {
  console.error('usage: node web/bench/site_frame.bench.mjs SITE/index.html [WIDTHxHEIGHT] [seconds]');
  process.exit(2);
}
const [width, height] = size.split('x').map(Number);
const browser = await puppeteer.launch({
  executablePath: process.env.SKYBAKE_CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
const page = await browser.newPage();
await page.setViewport({ width, height });
await page.goto(`${pathToFileURL(resolve(site)).href}?elevation=20&azimuth=135`);
await page.waitForFunction('(window.skybakeSiteFrames ?? 0) >= 3 || window.skybakeSite?.error', { timeout: 300000 });
const frameTime = async (mode) => {
  await page.evaluate((m) => window.skybakeSite.setShading(m), mode);
  await new Promise((r) => setTimeout(r, 1500)); // compile, settle
  const f0 = await page.evaluate('window.skybakeSiteFrames');
  const t0 = Date.now();
  await new Promise((r) => setTimeout(r, Number(seconds) * 1000));
  const frames = (await page.evaluate('window.skybakeSiteFrames')) - f0;
  return (Date.now() - t0) / Math.max(1, frames);
};
const base = await frameTime('flat');
const prt = await frameTime('PRT');
const glossy = await frameTime('PRT + glossy');
const sun = await frameTime('sun');
const base2 = await frameTime('flat');
const mean = (base + base2) / 2;
console.log(`${width}x${height}: flat (baseline) ${base.toFixed(0)} / ${base2.toFixed(0)} ms per frame; ` +
  `PRT + network sky ${prt.toFixed(0)} ms (${(prt / mean).toFixed(2)} x), PRT + glossy ${glossy.toFixed(0)} ms (${(glossy / mean).toFixed(2)} x), ` +
  `sun only ${sun.toFixed(0)} ms (${(sun / mean).toFixed(2)} x)`);
await browser.close();
