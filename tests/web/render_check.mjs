#!/usr/bin/env node
// Renders a shadowbake bake's scene.glb with three.js in headless Chromium and checks, pixel by
// pixel, that what three.js shows is what the bake's own lightmap PNGs hold.
//
//   node tests/web/render_check.mjs BAKE_DIR [--screenshot OUT.png] [--view X,Y,Z]
//        [--size WxH] [--step PX]
//
// BAKE_DIR is a `shadowbake bake ... --encoding png --gltf` output: manifest.json, the PNG
// lightmaps (per receiver, or atlases) and scene.glb.
//
// How:
// - A static HTTP server (node:http, 127.0.0.1, a random port) serves render_page.html/.js,
//   three.js from tests/web/node_modules and the bake folder. Nothing else is fetched.
// - render_page.js loads the .glb with GLTFLoader and a MOZ_lightmap plugin that binds the
//   texture through three.js's own parser.assignTexture (three.js applies texCoord and
//   KHR_texture_transform), renders unlit so a pixel's linear colour is the lightmap value,
//   and raycasts a grid of pixels for check points (receiver, TEXCOORD_1 at the pixel centre).
// - Here, independently of three.js's texture path, the expected value at each check point is
//   sampled from the PNG that manifest.json names: bilinear, texel centres at (i + 0.5) / w,
//   clamped to the edge, times the manifest's scale; for an atlas through the manifest's
//   scale_offset (Unity's, v up), which cross-checks the glTF's KHR_texture_transform.
// - The screenshot's bytes (not the canvas) are compared with it.
//
// Exit 0 when every check passes, 1 when one fails, 2 on a usage error.

import { createServer } from 'node:http';
import { existsSync } from 'node:fs';
import { readFile, writeFile, mkdtemp, rm } from 'node:fs/promises';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { PNG } from 'pngjs';
import puppeteer from 'puppeteer-core';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const CHROMIUM = process.env.CHROMIUM ?? '/usr/bin/chromium';

// Headless Chromium without a GPU: WebGL through ANGLE on SwiftShader (named explicitly so a
// machine with a GPU renders the same way), colours untouched by a display profile.
const CHROMIUM_FLAGS = [
  '--no-sandbox', // needed as root (CI runs as root)
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  '--use-angle=swiftshader',
  '--enable-unsafe-swiftshader',
  '--force-color-profile=srgb',
];

// The check's tolerance, in 8-bit sRGB steps (see checkPoint).
const TOLERANCE_BYTES = 3;
const MIN_POINTS = 50;
const MIN_SHADOW = 10; // expected value < SHADOW_BELOW
const MIN_LIT = 10; // expected value > LIT_ABOVE
const SHADOW_BELOW = 0.5;
const LIT_ABOVE = 0.8;

function usage(message) {
  if (message) console.error(`render_check: ${message}`);
  console.error('usage: node render_check.mjs BAKE_DIR [--screenshot OUT.png] [--view X,Y,Z] ' +
    '[--size WxH] [--step PX]');
  process.exit(2);
}

function parseArgs(argv) {
  const opts = { bakeDir: null, screenshot: null, view: '0.45,0.8,1', width: 800, height: 600, step: 8 };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) usage(`${a} needs a value`);
      return argv[++i];
    };
    if (a === '--screenshot') opts.screenshot = value();
    else if (a === '--view') {
      opts.view = value();
      const v = opts.view.split(',').map(Number);
      if (v.length !== 3 || v.some((x) => !Number.isFinite(x)) || v.every((x) => x === 0)) {
        usage('--view wants X,Y,Z, a direction from the scene to the camera (glTF frame, Y up)');
      }
    } else if (a === '--size') {
      const m = /^(\d+)x(\d+)$/.exec(value());
      if (!m) usage('--size wants WxH, e.g. 800x600');
      opts.width = Number(m[1]);
      opts.height = Number(m[2]);
    } else if (a === '--step') {
      opts.step = Number(value());
      if (!(opts.step >= 1)) usage('--step wants a number of pixels >= 1');
    } else if (a.startsWith('-')) usage(`unknown option ${a}`);
    else if (opts.bakeDir === null) opts.bakeDir = a;
    else usage(`unexpected argument ${a}`);
  }
  if (!opts.bakeDir) usage();
  return opts;
}

// ---- the expected values, from the bake's own files -------------------------------------------

const pngCache = new Map();
async function loadPng(file) {
  if (!pngCache.has(file)) {
    const png = PNG.sync.read(await readFile(file));
    pngCache.set(file, { width: png.width, height: png.height, data: png.data }); // RGBA, 8 bit
  }
  return pngCache.get(file);
}

// Receiver name -> where its lightmap is: { image, coverage, scale, scaleOffset | null, label }.
async function receiverSources(bakeDir, manifest) {
  const sources = new Map();
  const atlases = manifest.atlases ?? [];
  for (const r of manifest.receivers ?? []) {
    if (r.atlas) {
      const atlas = atlases.find((a) => a.index === r.atlas.index);
      if (!atlas) throw new Error(`receiver '${r.name}': atlas ${r.atlas.index} is not in manifest.atlases`);
      const lm = atlas.files.lightmap;
      if (lm.encoding !== 'png') throw new Error(`atlas ${atlas.index}: lightmap encoding ${lm.encoding}, wants png`);
      sources.set(r.name, {
        image: await loadPng(path.join(bakeDir, lm.file)),
        coverage: atlas.files.coverage ? await loadPng(path.join(bakeDir, atlas.files.coverage.file)) : null,
        scale: lm.scale ?? 1,
        scaleOffset: r.atlas.scale_offset,
        label: `${lm.file} rect ${JSON.stringify(r.atlas.rect)}`,
      });
    } else {
      const lm = r.files?.lightmap;
      if (!lm) throw new Error(`receiver '${r.name}' has no files.lightmap in the manifest`);
      if (lm.encoding !== 'png') throw new Error(`receiver '${r.name}': lightmap encoding ${lm.encoding}, wants png`);
      sources.set(r.name, {
        image: await loadPng(path.join(bakeDir, lm.file)),
        coverage: r.files.coverage ? await loadPng(path.join(bakeDir, r.files.coverage.file)) : null,
        scale: lm.scale ?? 1,
        scaleOffset: null,
        label: lm.file,
      });
    }
  }
  return sources;
}

// Continuous texel coordinates (texel centres at integers, row 0 at the top of the image) of the
// point whose glTF TEXCOORD_1 is (u, vDown).
function texelCoords(src, u, vDown) {
  const { width: w, height: h } = src.image;
  let au = u;
  let avUp = 1 - vDown; // glTF's v runs down the image; the manifest's (Unity's) runs up
  if (src.scaleOffset) {
    const [sx, sy, ox, oy] = src.scaleOffset;
    au = u * sx + ox;
    avUp = avUp * sy + oy;
  }
  // Image row 0 is v_up = 1. Texel i's centre is at (i + 0.5) / w.
  return [au * w - 0.5, (1 - avUp) * h - 0.5];
}

const clampIndex = (i, n) => Math.min(n - 1, Math.max(0, i));

function texel(img, i, j, c) {
  return img.data[(clampIndex(j, img.height) * img.width + clampIndex(i, img.width)) * 4 + c];
}

// Bilinear, clamped to the edge: the lightmap's linear value (byte / 255 x scale) per channel.
function bilinear(src, x, y) {
  const i0 = Math.floor(x), j0 = Math.floor(y);
  const fx = x - i0, fy = y - j0;
  const out = [];
  for (let c = 0; c < 3; c++) {
    const a = texel(src.image, i0, j0, c) * (1 - fx) + texel(src.image, i0 + 1, j0, c) * fx;
    const b = texel(src.image, i0, j0 + 1, c) * (1 - fx) + texel(src.image, i0 + 1, j0 + 1, c) * fx;
    out.push((a * (1 - fy) + b * fy) / 255 * src.scale);
  }
  return out;
}

// The texels within one texel of (x, y): those whose square [i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]
// comes within one texel of the point in u and in v (centres less than 1.5 texels away), clamped
// to the image. That holds every texel bilinear filtering can use if the sample point moves by
// up to half a texel.
function neighbourhood(img, x, y) {
  const list = [];
  for (let j = Math.ceil(y - 1.5); j <= Math.floor(y + 1.5); j++) {
    for (let i = Math.ceil(x - 1.5); i <= Math.floor(x + 1.5); i++) {
      list.push([clampIndex(i, img.width), clampIndex(j, img.height)]);
    }
  }
  return list;
}

// Linear [0, 1] -> the 8-bit sRGB byte three.js writes (sRGB output, no tone mapping).
function srgbByte(linear) {
  const v = Math.min(1, Math.max(0, linear));
  const s = v <= 0.0031308 ? v * 12.92 : 1.055 * Math.pow(v, 1 / 2.4) - 0.055;
  return Math.round(s * 255);
}

// The pass rule: at a check point, in each of R, G and B, the rendered byte must lie within
// [min, max] of the expected sRGB bytes of the lightmap texels within one texel of the point
// (see neighbourhood), widened by TOLERANCE_BYTES (3/255) on each side. Bilinear filtering of
// those texels can only give values in that range; the band absorbs small differences between
// where the raycast and the rasteriser put the pixel's UV (near a hard shadow edge a few
// hundredths of a texel matter), and the 3/255 the GPU's filtering precision and rounding.
// A wrong UV set, a missing v flip, a wrong atlas rectangle or the wrong texture lands on other
// texels and leaves the band.
function checkPoint(src, point, screenshot) {
  const [x, y] = texelCoords(src, point.uv1[0], point.uv1[1]);
  const expected = bilinear(src, x, y);
  const near = neighbourhood(src.image, x, y);
  const rendered = [0, 1, 2].map((c) => screenshot.data[(point.py * screenshot.width + point.px) * 4 + c]);
  let excess = 0; // bytes outside the band, worst channel
  let diff = 0; // |rendered - expected (bilinear)|, worst channel
  const bands = [];
  for (let c = 0; c < 3; c++) {
    const bytes = near.map(([i, j]) => srgbByte(texel(src.image, i, j, c) / 255 * src.scale));
    const lo = Math.min(...bytes), hi = Math.max(...bytes);
    bands.push([lo, hi]);
    excess = Math.max(excess, lo - TOLERANCE_BYTES - rendered[c], rendered[c] - hi - TOLERANCE_BYTES);
    diff = Math.max(diff, Math.abs(rendered[c] - srgbByte(expected[c])));
  }
  const covered = src.coverage ? near.some(([i, j]) => texel(src.coverage, i, j, 0) > 0) : true;
  const mean = (expected[0] + expected[1] + expected[2]) / 3;
  return { ...point, texel: [x, y], expected, mean, bands, rendered, diff, excess, covered,
    pass: excess <= 0 };
}

// ---- serving the page, driving Chromium -------------------------------------------------------

const MIME = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript',
  '.json': 'application/json', '.glb': 'model/gltf-binary', '.gltf': 'model/gltf+json',
  '.png': 'image/png', '.bin': 'application/octet-stream' };

// Serves / and the page's module from tests/web, /node_modules/three/ from tests/web's
// node_modules, and /bake/ from the bake folder; nothing outside those folders.
function startServer(bakeDir) {
  const roots = [
    ['/node_modules/three/', path.join(HERE, 'node_modules', 'three')],
    ['/bake/', path.resolve(bakeDir)],
  ];
  const pages = { '/': 'render_page.html', '/render_page.js': 'render_page.js' };
  const server = createServer(async (req, res) => {
    try {
      const url = new URL(req.url, 'http://127.0.0.1');
      const pathname = decodeURIComponent(url.pathname);
      let file = pages[pathname] ? path.join(HERE, pages[pathname]) : null;
      for (const [prefix, root] of roots) {
        if (!file && pathname.startsWith(prefix)) {
          const candidate = path.resolve(root, '.' + pathname.slice(prefix.length - 1));
          if (candidate.startsWith(root + path.sep)) file = candidate;
        }
      }
      if (!file) {
        res.writeHead(404).end('not found');
        return;
      }
      const body = await readFile(file);
      res.writeHead(200, { 'Content-Type': MIME[path.extname(file)] ?? 'application/octet-stream',
        'Cache-Control': 'no-store' });
      res.end(body);
    } catch {
      res.writeHead(404).end('not found');
    }
  });
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(0, '127.0.0.1', () => resolve(server));
  });
}

async function renderInChromium(opts, glbName) {
  const server = await startServer(opts.bakeDir);
  const profile = await mkdtemp(path.join(tmpdir(), 'render-check-chromium-'));
  let browser;
  const log = [];
  try {
    browser = await puppeteer.launch({
      executablePath: CHROMIUM,
      headless: true,
      userDataDir: profile,
      args: CHROMIUM_FLAGS,
      protocolTimeout: 180_000,
    });
    const page = await browser.newPage();
    page.on('console', (m) => log.push(`console.${m.type()}: ${m.text()}`));
    page.on('pageerror', (e) => log.push(`pageerror: ${e.message}`));
    page.on('requestfailed', (r) => log.push(`requestfailed: ${r.url()} ${r.failure()?.errorText}`));
    await page.setViewport({ width: opts.width, height: opts.height, deviceScaleFactor: 1 });
    const { port } = server.address();
    const query = new URLSearchParams({ glb: `/bake/${glbName}`, width: opts.width,
      height: opts.height, view: opts.view, step: opts.step });
    await page.goto(`http://127.0.0.1:${port}/?${query}`, { waitUntil: 'load' });
    await page.waitForFunction(() => window.__renderCheck !== undefined,
      { timeout: 120_000, polling: 100 });
    const result = await page.evaluate(() => window.__renderCheck);
    if (result.status !== 'done') {
      throw new Error(`the page failed: ${result.message}\n${log.join('\n')}`);
    }
    const png = await page.screenshot({ type: 'png',
      clip: { x: 0, y: 0, width: opts.width, height: opts.height } });
    return { result, png: Buffer.from(png), log };
  } finally {
    if (browser) await browser.close();
    server.close();
    await rm(profile, { recursive: true, force: true });
  }
}

// ---- main ---------------------------------------------------------------------------------------

const fmt = (x, n = 3) => Number(x).toFixed(n);

async function main() {
  const opts = parseArgs(process.argv.slice(2));
  const t0 = performance.now();
  const manifestPath = path.join(opts.bakeDir, 'manifest.json');
  if (!existsSync(manifestPath)) {
    console.log(`render_check: FAIL: ${manifestPath} not found (is ${opts.bakeDir} a shadowbake bake folder?)`);
    return 1;
  }
  const manifest = JSON.parse(await readFile(manifestPath, 'utf8'));
  const glbName = manifest.gltf ?? 'scene.glb';
  if (!existsSync(path.join(opts.bakeDir, glbName))) {
    console.log(`render_check: FAIL: ${path.join(opts.bakeDir, glbName)} not found (bake with --gltf)`);
    return 1;
  }
  const sources = await receiverSources(opts.bakeDir, manifest);

  const { result, png } = await renderInChromium(opts, glbName);
  const tRendered = performance.now();
  if (opts.screenshot) await writeFile(opts.screenshot, png);
  const shot = PNG.sync.read(png);
  if (shot.width !== opts.width || shot.height !== opts.height) {
    throw new Error(`the screenshot is ${shot.width}x${shot.height}, wanted ${opts.width}x${opts.height}`);
  }

  const failures = [];
  console.log(`render_check ${opts.bakeDir}: three.js r${result.threeRevision} on ${result.glRenderer}`);
  for (const [name, r] of Object.entries(result.receivers)) {
    const t = r.texture;
    const src = sources.get(name);
    console.log(`  ${name}: lightMap ${t.size?.join('x')} channel ${t.channel}, ` +
      `offset (${t.offset.map((v) => fmt(v, 6)).join(', ')}) repeat (${t.repeat.map((v) => fmt(v, 6)).join(', ')}), ` +
      `${t.magFilter}/${t.minFilter} ${t.wrapS}/${t.wrapT}, colorSpace ${t.colorSpace || 'NoColorSpace'}, ` +
      `intensity ${r.intensity}; expected from ${src ? src.label + ' scale ' + src.scale : '(none)'}`);
    if (!src) failures.push(`the glTF has a receiver '${name}' that manifest.json does not list`);
    if (t.minFilter !== 'LINEAR' || t.magFilter !== 'LINEAR') {
      failures.push(`'${name}': the lightmap is filtered ${t.magFilter}/${t.minFilter}, wants LINEAR/LINEAR (no mipmaps)`);
    }
  }
  for (const name of sources.keys()) {
    if (!result.receivers[name]) failures.push(`manifest.json's receiver '${name}' is not in the glTF`);
  }

  const checked = result.points.filter((p) => sources.has(p.name))
    .map((p) => checkPoint(sources.get(p.name), p, shot));
  const bad = checked.filter((c) => !c.pass);
  const uncovered = checked.filter((c) => !c.covered);
  const shadow = checked.filter((c) => c.mean < SHADOW_BELOW).length;
  const lit = checked.filter((c) => c.mean > LIT_ABOVE).length;
  const perReceiver = {};
  for (const c of checked) perReceiver[c.name] = (perReceiver[c.name] ?? 0) + 1;
  const worstDiff = checked.reduce((m, c) => Math.max(m, c.diff), 0);
  const worstExcess = checked.reduce((m, c) => Math.max(m, c.excess), -Infinity);

  if (checked.length < MIN_POINTS) failures.push(`only ${checked.length} check points, wants >= ${MIN_POINTS}`);
  if (shadow < MIN_SHADOW) failures.push(`only ${shadow} check points in shadow (< ${SHADOW_BELOW}), wants >= ${MIN_SHADOW}`);
  if (lit < MIN_LIT) failures.push(`only ${lit} lit check points (> ${LIT_ABOVE}), wants >= ${MIN_LIT}`);
  if (bad.length) failures.push(`${bad.length} of ${checked.length} check points render outside the expected band`);
  // The baker's coverage image says which texels its UV charts cover: a point of a receiver's
  // surface must land on (or within one texel of) a covered texel, whatever the texture holds.
  if (uncovered.length) {
    failures.push(`${uncovered.length} check points land on lightmap texels that no UV chart covers ` +
      `(coverage 0 within one texel)`);
  }

  const worstLine = (c) => `    ${c.name} pixel (${c.px}, ${c.py}) uv1 (${fmt(c.uv1[0], 4)}, ${fmt(c.uv1[1], 4)}) ` +
    `texel (${fmt(c.texel[0], 1)}, ${fmt(c.texel[1], 1)}): rendered [${c.rendered.join(', ')}], ` +
    `expected [${c.expected.map(srgbByte).join(', ')}] band ${c.bands.map(([lo, hi]) => `${lo}..${hi}`).join(' ')}` +
    `${c.pass ? '' : `, ${c.excess} byte(s) outside`}${c.covered ? '' : ', uncovered texels'}`;

  const seconds = (performance.now() - t0) / 1000;
  console.log(`  ${checked.length} check points of ${result.candidates} hit pixels ` +
    `(${Object.entries(perReceiver).map(([n, k]) => `${n} ${k}`).join(', ')}); ` +
    `${shadow} in shadow (< ${SHADOW_BELOW}), ${lit} lit (> ${LIT_ABOVE}); ` +
    `worst |rendered - expected| ${worstDiff} byte(s), ` +
    `worst outside the band ${Math.max(0, worstExcess)} byte(s) (tolerance ${TOLERANCE_BYTES}); ` +
    `${fmt(seconds, 1)} s (page: load ${fmt(result.ms.load / 1000, 2)} s, render ${fmt(result.ms.render / 1000, 2)} s, ` +
    `pick ${fmt(result.ms.pick / 1000, 2)} s; browser total ${fmt((tRendered - t0) / 1000, 1)} s)`);
  if (opts.screenshot) console.log(`  screenshot: ${opts.screenshot}`);

  if (failures.length) {
    console.log(`render_check: FAIL: ${failures.join('; ')}`);
    const worst = [...checked].sort((a, b) => b.excess - a.excess || b.diff - a.diff)
      .filter((c) => !c.pass || !c.covered).slice(0, 10);
    if (worst.length) {
      console.log('  worst points:');
      for (const c of worst) console.log(worstLine(c));
    }
    return 1;
  }
  console.log(`render_check: PASS`);
  return 0;
}

main().then(
  (code) => { process.exitCode = code; },
  (err) => {
    console.error(`render_check: FAIL: ${err?.stack ?? err}`);
    process.exitCode = 1;
  });
