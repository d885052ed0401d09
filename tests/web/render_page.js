// The page that render_check.mjs opens in headless Chromium. It loads a shadowbake .glb with
// three.js's GLTFLoader, binds each material's MOZ_lightmap texture as the material's lightMap
// through three.js's own parser.assignTexture (so three.js applies texCoord -> channel and
// KHR_texture_transform itself), renders every receiver unlit (white x lightmap) so that a
// pixel's linear colour is the lightmap's value, and then raycasts a grid of pixels to pick
// check points. It reports through window.__renderCheck: { status: 'done' | 'error', ... }.
//
// URL parameters: glb (the file's URL), width, height, view (x,y,z: the direction from the
// scene's centre to the camera, glTF frame), step (grid spacing of the candidate pixels).

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const params = new URLSearchParams(location.search);
const WIDTH = Number(params.get('width') ?? 800);
const HEIGHT = Number(params.get('height') ?? 600);
const VIEW = (params.get('view') ?? '0.45,0.8,1').split(',').map(Number);
const STEP = Number(params.get('step') ?? 8);
const GLB = params.get('glb') ?? '/bake/scene.glb';

// Half the distance, in pixels, to the four neighbours that must look like the same smooth
// surface for a pixel to be kept (see pickPoints).
const NEIGHBOUR_PX = 3;
// Keep only surfaces within 60 degrees of facing the camera.
const MIN_FACING_COS = 0.5;

// The loader plugin for MOZ_lightmap: { index, texCoord, intensity, extensions } on a material.
class MozLightmapPlugin {
  constructor(parser) {
    this.parser = parser;
    this.name = 'MOZ_lightmap';
  }

  extendMaterialParams(materialIndex, materialParams) {
    const materialDef = this.parser.json.materials[materialIndex];
    const ext = materialDef.extensions?.[this.name];
    if (!ext) return Promise.resolve();
    materialParams.lightMapIntensity = ext.intensity ?? 1.0;
    // No colour space argument: the texture keeps three's default (NoColorSpace), so the
    // sampled value is the raw byte / 255, as MOZ_lightmap's linear values need.
    return this.parser.assignTexture(materialParams, 'lightMap', ext);
  }
}

function fail(message) {
  window.__renderCheck = { status: 'error', message: String(message) };
}

// The name of the glTF node a three.js object came from (walking up from a primitive's mesh).
function nodeName(parser, object) {
  for (let o = object; o; o = o.parent) {
    const assoc = parser.associations.get(o);
    if (assoc && assoc.nodes !== undefined) return parser.json.nodes[assoc.nodes].name ?? o.name;
  }
  return object.name;
}

function describeTexture(t) {
  const filter = (f) => ({ [THREE.NearestFilter]: 'NEAREST', [THREE.LinearFilter]: 'LINEAR',
    [THREE.LinearMipmapLinearFilter]: 'LINEAR_MIPMAP_LINEAR',
    [THREE.NearestMipmapNearestFilter]: 'NEAREST_MIPMAP_NEAREST',
    [THREE.LinearMipmapNearestFilter]: 'LINEAR_MIPMAP_NEAREST',
    [THREE.NearestMipmapLinearFilter]: 'NEAREST_MIPMAP_LINEAR' }[f] ?? String(f));
  const wrap = (w) => ({ [THREE.ClampToEdgeWrapping]: 'CLAMP_TO_EDGE',
    [THREE.RepeatWrapping]: 'REPEAT', [THREE.MirroredRepeatWrapping]: 'MIRRORED_REPEAT' }[w] ?? String(w));
  return {
    channel: t.channel,
    offset: [t.offset.x, t.offset.y],
    repeat: [t.repeat.x, t.repeat.y],
    rotation: t.rotation,
    colorSpace: t.colorSpace,
    flipY: t.flipY,
    minFilter: filter(t.minFilter),
    magFilter: filter(t.magFilter),
    wrapS: wrap(t.wrapS),
    wrapT: wrap(t.wrapT),
    size: t.image ? [t.image.width, t.image.height] : null,
  };
}

// Looks along -dir and frames the given world-space points: the camera's target is moved
// sideways and the camera moved along dir until the points' projection is centred and fills 92%
// of the frame in its tighter direction.
function fitCamera(camera, pointsWorld, dir) {
  const box = new THREE.Box3().setFromPoints(pointsWorld);
  const target = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
  const d = new THREE.Vector3(...dir).normalize();
  const tanV = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.92;
  const tanH = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) * camera.aspect * 0.92;
  const place = (dist) => {
    camera.position.copy(target).addScaledVector(d, dist);
    camera.lookAt(target);
    camera.updateMatrixWorld(true);
  };
  // The points' extent in the frame, in units of the 92% frame's half-size (NDC-like).
  const extent = () => {
    const view = camera.matrixWorldInverse;
    const e = { minX: Infinity, maxX: -Infinity, minY: Infinity, maxY: -Infinity, behind: false };
    const p = new THREE.Vector3();
    for (const w of pointsWorld) {
      p.copy(w).applyMatrix4(view);
      const depth = -p.z;
      if (depth <= radius * 1e-3) { e.behind = true; continue; }
      const x = p.x / (depth * tanH), y = p.y / (depth * tanV);
      e.minX = Math.min(e.minX, x); e.maxX = Math.max(e.maxX, x);
      e.minY = Math.min(e.minY, y); e.maxY = Math.max(e.maxY, y);
    }
    return e;
  };
  const fits = (dist) => {
    place(dist);
    const e = extent();
    return !e.behind && e.minX >= -1 && e.maxX <= 1 && e.minY >= -1 && e.maxY <= 1;
  };
  const fitDistance = () => {
    let lo = radius * 0.01, hi = radius * 100;
    for (let i = 0; i < 50; i++) {
      const mid = (lo + hi) / 2;
      if (fits(mid)) hi = mid; else lo = mid;
    }
    place(hi);
    return hi;
  };
  let dist = fitDistance();
  for (let iter = 0; iter < 10; iter++) {
    const e = extent();
    const cx = (e.minX + e.maxX) / 2, cy = (e.minY + e.maxY) / 2;
    const right = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 0);
    const up = new THREE.Vector3().setFromMatrixColumn(camera.matrixWorld, 1);
    target.addScaledVector(right, cx * dist * tanH).addScaledVector(up, cy * dist * tanV);
    dist = fitDistance();
  }
  camera.near = Math.max(dist - radius * 2, radius * 0.01);
  camera.far = dist + radius * 2;
  camera.updateProjectionMatrix();
}

// The ray through the centre of screen pixel (px, py), row 0 at the top: where the rasteriser
// samples that pixel.
function setRay(raycaster, camera, px, py) {
  const ndc = new THREE.Vector2((px + 0.5) / WIDTH * 2 - 1, 1 - (py + 0.5) / HEIGHT * 2);
  raycaster.setFromCamera(ndc, camera);
}

function firstHit(raycaster, camera, meshes, px, py) {
  setRay(raycaster, camera, px, py);
  const hits = raycaster.intersectObjects(meshes, false);
  if (hits.length === 0) return null;
  const h = hits[0];
  const normalMatrix = new THREE.Matrix3().getNormalMatrix(h.object.matrixWorld);
  h.worldFaceNormal = h.face.normal.clone().applyMatrix3(normalMatrix).normalize();
  return h;
}

// Candidate pixels on a grid. A pixel is kept when its surface faces the camera (within 60
// degrees) and the four pixels NEIGHBOUR_PX away hit the same object, on a face whose normal is
// within ~11 degrees of the centre's, with the lightmap UVs changing linearly across the pixel
// (no UV seam, crease or object edge nearby, where the rasteriser and the raycast could disagree
// by a fraction of a pixel).
function pickPoints(parser, camera, meshes) {
  const raycaster = new THREE.Raycaster();
  const points = [];
  let candidates = 0;
  const R = NEIGHBOUR_PX;
  for (let py = STEP / 2 | 0; py < HEIGHT - R; py += STEP) {
    if (py < R) continue;
    for (let px = STEP / 2 | 0; px < WIDTH - R; px += STEP) {
      if (px < R) continue;
      const h = firstHit(raycaster, camera, meshes, px, py);
      if (!h || !h.uv1) continue;
      candidates++;
      const facing = -raycaster.ray.direction.dot(h.worldFaceNormal);
      if (facing < MIN_FACING_COS) continue;
      const nb = [[px - R, py], [px + R, py], [px, py - R], [px, py + R]].map(
        ([x, y]) => firstHit(raycaster, camera, meshes, x, y));
      if (nb.some((n) => !n || n.object !== h.object || !n.uv1 ||
        n.worldFaceNormal.dot(h.worldFaceNormal) < 0.98)) continue;
      const linear = (a, b) => {
        const da = a.uv1.clone().sub(h.uv1), db = b.uv1.clone().sub(h.uv1);
        const second = da.clone().add(db).length();
        return second <= 0.2 * Math.max(da.length(), db.length()) + 1e-5;
      };
      if (!linear(nb[0], nb[1]) || !linear(nb[2], nb[3])) continue;
      points.push({
        px, py,
        name: nodeName(parser, h.object),
        uv1: [h.uv1.x, h.uv1.y],
        uv: h.uv ? [h.uv.x, h.uv.y] : null,
        facing,
      });
    }
  }
  return { points, candidates };
}

async function main() {
  const t0 = performance.now();
  const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  renderer.setSize(WIDTH, HEIGHT);
  renderer.outputColorSpace = THREE.SRGBColorSpace;
  renderer.toneMapping = THREE.NoToneMapping;
  document.body.appendChild(renderer.domElement);
  const gl = renderer.getContext();
  const debugInfo = gl.getExtension('WEBGL_debug_renderer_info');
  const glRenderer = gl.getParameter(debugInfo ? debugInfo.UNMASKED_RENDERER_WEBGL : gl.RENDERER);

  const loader = new GLTFLoader();
  loader.register((parser) => new MozLightmapPlugin(parser));
  const gltf = await loader.loadAsync(GLB);
  const tLoaded = performance.now();

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x3a3f4b);
  scene.add(gltf.scene);
  scene.updateMatrixWorld(true);

  const meshes = [];          // everything a ray may hit
  const receiverMeshes = [];  // those with a lightmap: the camera frames them
  const receivers = {};
  const problems = [];
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    const name = nodeName(gltf.parser, o);
    const m = o.material;
    if (!o.geometry.attributes.uv1) {
      // A blocker: shadowbake writes it without lightmap UVs or lightmap. It hides what lies
      // behind it (raycasts stop on it) and is drawn plain grey; no check point lies on it.
      const plain = new THREE.MeshBasicMaterial({ color: 0x808080, side: m.side });
      plain.name = m.name;
      o.material = plain;
      meshes.push(o);
      return;
    }
    if (!m.lightMap) {
      problems.push(`'${name}': its material '${m.name}' has no lightMap (MOZ_lightmap missing?)`);
      return;
    }
    // MeshBasicMaterial adds lightMap * lightMapIntensity / PI (three's meshbasic shader:
    // "lightMapTexel.rgb * lightMapIntensity * RECIPROCAL_PI"), times the white colour; so
    // intensity * PI makes the rendered linear colour the lightmap's value.
    const basic = new THREE.MeshBasicMaterial({
      color: 0xffffff,
      lightMap: m.lightMap,
      lightMapIntensity: m.lightMapIntensity * Math.PI,
      side: m.side,
    });
    basic.name = m.name;
    o.material = basic;
    meshes.push(o);
    receiverMeshes.push(o);
    receivers[name] = { material: m.name, intensity: m.lightMapIntensity,
      texture: describeTexture(m.lightMap) };
  });
  if (problems.length) return fail(problems.join('; '));
  if (receiverMeshes.length === 0) return fail('the glTF has no meshes with a lightmap');

  const camera = new THREE.PerspectiveCamera(40, WIDTH / HEIGHT, 0.01, 1000);
  const vertices = [];
  for (const mesh of receiverMeshes) {
    const pos = mesh.geometry.attributes.position;
    for (let i = 0; i < pos.count; i++) {
      vertices.push(new THREE.Vector3().fromBufferAttribute(pos, i).applyMatrix4(mesh.matrixWorld));
    }
  }
  fitCamera(camera, vertices, VIEW);

  renderer.render(scene, camera);
  gl.finish();
  const tRendered = performance.now();

  const { points, candidates } = pickPoints(gltf.parser, camera, meshes);
  const tPicked = performance.now();

  window.__renderCheck = {
    status: 'done',
    glRenderer,
    threeRevision: THREE.REVISION,
    receivers,
    camera: { position: camera.position.toArray(), fov: camera.fov },
    candidates,
    points,
    ms: { load: tLoaded - t0, render: tRendered - tLoaded, pick: tPicked - tRendered },
  };
}

main().catch((err) => fail(err && err.stack ? err.stack : err));
