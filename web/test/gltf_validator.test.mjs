// skybake's glTF outputs against the Khronos glTF validator (npm
// `gltf-validator`): bakes written into users' documents, converted meshes
// and the sky as EXT_lights_image_based, from real sample assets. Each must
// have no error and no warning. Needs SKYBAKE_CLI and SKYBAKE_TEST_DATA.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { validateBytes } from 'gltf-validator';

const cli = process.env.SKYBAKE_CLI;
const models = process.env.SKYBAKE_ASSIMP_MODELS || '/usr/share/assimp/models';
const weights = join(process.env.SKYBAKE_TEST_DATA, 'neural', 'v3_earth_default.json');
const dir = mkdtempSync(join(tmpdir(), 'skybake-gltf-validator-'));

function skybake(...args) {
  const r = spawnSync(cli, args, { encoding: 'utf8' });
  assert.equal(r.status, 0, `skybake ${args.join(' ')}: ${r.stderr}`);
}

// External resources of a .gltf (its buffers and images), read from its folder.
function externalResourceFunction(folder) {
  return (uri) => Promise.resolve(new Uint8Array(readFileSync(join(folder, decodeURIComponent(uri)))));
}

async function validate(file) {
  const report = await validateBytes(new Uint8Array(readFileSync(file)), {
    uri: file,
    maxIssues: 100,
    externalResourceFunction: externalResourceFunction(dir),
  });
  const serious = report.issues.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} ${m.pointer ?? ''}: ${m.message}`);
  return { report, serious };
}

const box = join(models, 'glTF2', 'BoxTextured-glTF-Binary', 'BoxTextured.glb');
const boxExternal = join(models, 'glTF2', 'BoxTextured-glTF', 'BoxTextured.gltf');
const morph = join(models, 'glTF2', 'glTF-Sample-Models', 'AnimatedMorphCube-glTF', 'AnimatedMorphCube.gltf');
const engine = join(models, 'glTF2', '2CylinderEngine-glTF-Binary', '2CylinderEngine.glb');
const spider = join(models, 'OBJ', 'spider.obj');

// Suzanne exported by Blender (the same script as the C++ Blender tests), or
// null when there is no blender.
function blenderSuzanne() {
  const out = join(dir, 'suzanne.glb');
  const script = join(process.env.SKYBAKE_TEST_DATA, 'blender', 'make_suzanne.py');
  const r = spawnSync('blender', ['-b', '--factory-startup', '--python', script, '--', out, 'material'], { encoding: 'utf8' });
  return r.status === 0 ? out : null;
}

const cases = [
  ['ao into a user .glb', 'box_ao.glb', (out) => skybake('ao', box, '--rule', 'lebedev:194', '-o', out)],
  ['ao with an occlusion texture into a Blender export', 'suzanne_ao_tex.glb', (out, t) => {
    const suzanne = blenderSuzanne();
    if (!suzanne) {
      t.skip('no blender (scripts/install-deps.sh installs it)');
      return false;
    }
    skybake('ao', suzanne, '--rule', 'lebedev:86', '--texture', '64', '-o', out);
  }],
  ['prt bake into an animated, morphed document', 'morph_prt.glb', (out) => skybake('prt', 'bake', morph, '--order', '2', '--rule', 'lebedev:194', '-o', out)],
  ['prt bake of 2CylinderEngine (shared meshes)', 'engine_prt.glb', (out) => skybake('prt', 'bake', engine, '--order', '2', '--rule', 'lebedev:50', '-o', out)],
  ['mesh convert of an OBJ', 'spider.glb', (out) => skybake('mesh', 'convert', spider, '-o', out)],
  ['the sky as EXT_lights_image_based (.glb)', 'box_ibl.glb', (out) =>
    skybake('sky', 'sh', '--model', weights, '--sun-elevation-deg', '8', '--gltf', box, '-o', out)],
  ['the sky as EXT_lights_image_based (.gltf)', 'box_ibl.gltf', (out) =>
    skybake('sky', 'sh', '--model', weights, '--sun-elevation-deg', '8', '--gltf', boxExternal, '-o', out)],
];

for (const [name, file, make] of cases) {
  test(`gltf-validator: ${name}`, async (t) => {
    const out = join(dir, file);
    if (make(out, t) === false) return; // skipped
    const { report, serious } = await validate(out);
    assert.deepEqual(serious, [], `${file}: ${serious.join('; ')}`);
    assert.equal(report.issues.numErrors, 0);
    if (file.includes('ibl')) {
      // The validator does not know the vendor extension: it says so, and nothing worse.
      const codes = new Set(report.issues.messages.map((m) => m.code));
      assert.ok(codes.has('UNSUPPORTED_EXTENSION'));
    }
  });
}

test.after(() => rmSync(dir, { recursive: true, force: true }));
