// Frame time of a `skybake web` site in headless Chromium (WebGL 2 on
// SwiftShader unless --gpu), PRT shading with the network behind the model
// against its baseline in the same page run: the same model lit by the sun
// alone (the 'sun' shading: no sky light, same sky, same shadow map).
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
  await page.select('#shading', mode);
  await new Promise((r) => setTimeout(r, 1500)); // compile, settle
  const f0 = await page.evaluate('window.skybakeSiteFrames');
  const t0 = Date.now();
  await new Promise((r) => setTimeout(r, Number(seconds) * 1000));
  const frames = (await page.evaluate('window.skybakeSiteFrames')) - f0;
  return (Date.now() - t0) / Math.max(1, frames);
};
const base = await frameTime('sun');
const prt = await frameTime('PRT');
const base2 = await frameTime('sun');
console.log(`${width}x${height}: sun only (baseline) ${base.toFixed(0)} / ${base2.toFixed(0)} ms per frame, PRT + network sky ${prt.toFixed(0)} ms (${(prt / ((base + base2) / 2)).toFixed(2)} x the baseline)`);
await browser.close();
