#!/usr/bin/env node
// Validates a .glb (or .gltf) with the Khronos glTF-Validator.
//
//   node tests/web/validate_gltf.mjs FILE.glb
//
// Prints a one-line summary, every error, and the warnings (one line each), and a count of the
// infos and hints. Exits 0 iff the validator reports no error. The validator does not know
// MOZ_lightmap, so it reports UNSUPPORTED_EXTENSION as an info for it: that is expected.

import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

const SEVERITY = ['error', 'warning', 'info', 'hint'];

async function main() {
  const file = process.argv[2];
  if (!file || process.argv.length > 3) {
    console.error('usage: node validate_gltf.mjs FILE.glb');
    return 2;
  }
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0, // no limit
    // A .glb from shadowbake embeds everything; a .gltf beside its files may reference them.
    externalResourceFunction: (uri) =>
      readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then(
        (data) => new Uint8Array(data)),
  });

  const issues = report.issues;
  const messages = issues.messages || [];
  const info = report.info || {};
  const version = `glTF ${info.version ?? '?'}`;
  const generator = info.generator ? `, generator "${info.generator}"` : '';
  console.log(
    `${file}: ${issues.numErrors} error(s), ${issues.numWarnings} warning(s), ` +
    `${issues.numInfos} info(s), ${issues.numHints} hint(s) ` +
    `[${version}${generator}; ${info.drawCallCount ?? '?'} draw call(s), ` +
    `${info.materialCount ?? '?'} material(s), ${info.totalVertexCount ?? '?'} vertices, ` +
    `${info.totalTriangleCount ?? '?'} triangle(s), ${info.maxUVs ?? '?'} UV set(s); ` +
    `validator ${report.validatorVersion}]`);

  for (const m of messages) {
    if (m.severity === 0) {
      console.log(`  error   ${m.code} at ${m.pointer ?? m.offset ?? '?'}: ${m.message}`);
    }
  }
  for (const m of messages) {
    if (m.severity === 1) {
      console.log(`  warning ${m.code} at ${m.pointer ?? m.offset ?? '?'}: ${m.message}`);
    }
  }
  // Infos and hints: one line per code, with how many.
  const counts = new Map();
  for (const m of messages) {
    if (m.severity >= 2) {
      const key = `${SEVERITY[m.severity]} ${m.code}`;
      const seen = counts.get(key);
      counts.set(key, { n: (seen?.n ?? 0) + 1, example: seen?.example ?? m.message });
    }
  }
  for (const [key, { n, example }] of counts) {
    console.log(`  ${key} x${n} (e.g. ${example})`);
  }
  return issues.numErrors === 0 ? 0 : 1;
}

main().then(
  (code) => { process.exitCode = code; },
  (err) => {
    // validateBytes rejects when the input is not glTF at all (bad magic, unreadable JSON).
    console.error(`validate_gltf: ${err?.code === 'ENOENT' ? err.message : err?.stack ?? err}`);
    process.exitCode = 1;
  });
