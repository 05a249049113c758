// facelib's web player: plays an exported .glb (embedded by scene.js as base64) with its
// speech audio. three.js is bundled into dist/player.js at build time (npm run build), so
// the page needs no network. window.facelibPlayer is the page's API (used by the tests).
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { arkitMeshes, connectLive } from "./live.js";

const AUDIO_TRUST_S = 0.25; // the audio's clock is the face's within this of the page's
const scene = window.FACELIB_SCENE; // {glb: base64, look: {...}, audio, audioOffset}
const params = new URLSearchParams(window.location.search);

function decode(base64) {
  const text = atob(base64);
  const bytes = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) bytes[i] = text.charCodeAt(i);
  return bytes.buffer;
}

function lightDirection(azimuthDeg, elevationDeg) {
  const az = THREE.MathUtils.degToRad(azimuthDeg);
  const el = THREE.MathUtils.degToRad(elevationDeg);
  return new THREE.Vector3(Math.sin(az) * Math.cos(el), Math.sin(el), Math.cos(az) * Math.cos(el));
}

function setUp() {
  const canvas = document.getElementById("view");
  const size = /^(\d+)x(\d+)$/.exec(params.get("size") || ""); // ?size=320x240: a smaller view
  if (size) {
    [canvas.width, canvas.height] = [Number(size[1]), Number(size[2])];
    Object.assign(canvas.style, { width: `${size[1]}px`, height: `${size[2]}px` });
  }
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(1);
  const look = scene.look;
  const bg = params.get("bg") ? new THREE.Color("#" + params.get("bg")) : new THREE.Color().setRGB(
    ...look.background, THREE.SRGBColorSpace);
  const world = new THREE.Scene();
  world.background = bg;
  world.add(new THREE.AmbientLight(new THREE.Color().setRGB(...look.ambient), 1.0 * Math.PI));
  for (const light of look.lights) {
    const l = new THREE.DirectionalLight(new THREE.Color().setRGB(...light.color), light.intensity);
    l.position.copy(lightDirection(light.azimuth_deg, light.elevation_deg));
    world.add(l);
  }
  const camera = new THREE.PerspectiveCamera(look.camera.yfov_deg, 1, 0.01, 10);
  const controls = new OrbitControls(camera, canvas);
  return { canvas, renderer, world, camera, controls, look };
}

// the camera of facelib's renderer: on +z, centred on the neutral bounding box, far enough
// that the box times the margin fits both fields of view
function frameCamera(v, box) {
  const { camera, look, canvas } = v;
  const aspect = canvas.width / canvas.height;
  const centre = box.getCenter(new THREE.Vector3());
  const half = box.getSize(new THREE.Vector3()).multiplyScalar(look.camera.margin / 2);
  const tanY = Math.tan(THREE.MathUtils.degToRad(look.camera.yfov_deg) / 2);
  const distance = Math.max(half.y / tanY, half.x / (tanY * aspect), 1e-6) + half.z;
  camera.aspect = aspect;
  camera.position.set(centre.x, centre.y, centre.z + distance);
  camera.near = distance * 0.2;
  camera.far = distance * 5;
  camera.updateProjectionMatrix();
  v.controls.target.copy(centre);
  v.controls.update();
}

async function main() {
  const v = setUp();
  const gltf = await new GLTFLoader().parseAsync(decode(scene.glb), "");
  v.world.add(gltf.scene);
  if (document.body.dataset.live !== undefined) return liveMode(v, gltf);
  return fileMode(v, gltf);
}

function frameScene(v, gltf) {
  gltf.scene.updateMatrixWorld(true);
  const box = new THREE.Box3();
  gltf.scene.traverse((o) => { if (o.isMesh) { o.frustumCulled = false; box.expandByObject(o); } });
  frameCamera(v, box);
}

// the page of examples/live: a server URL (?server=ws://...), a line to say, the head
function liveMode(v, gltf) {
  frameScene(v, gltf); // the rest pose: the live frames set only the morph targets
  const head = arkitMeshes(gltf.scene);
  const status = document.getElementById("status");
  const server = document.getElementById("server");
  const line = document.getElementById("line");
  server.value = params.get("server") || server.value;
  const draw = () => v.renderer.render(v.world, v.camera);
  draw.canvas = v.canvas;
  const onStatus = (text) => { status.textContent = text; };
  let live = null;
  function connect() {
    if (live) live.close();
    live = connectLive(server.value, head, draw, { onStatus });
    window.facelibPlayer.live = live;
  }
  function say() {
    if (!live) connect();
    const text = line.value.trim();
    if (text) live.say(text);
    line.value = "";
  }
  document.getElementById("connect").addEventListener("click", connect);
  document.getElementById("say").addEventListener("click", say);
  line.addEventListener("keydown", (e) => { if (e.key === "Enter") say(); });
  window.facelibPlayer = { live: null, connect };
  connect();
  document.body.dataset.ready = "1";
}

function fileMode(v, gltf) {
  const mixer = new THREE.AnimationMixer(gltf.scene);
  const clip = gltf.animations[0];
  const duration = scene.nFrames > 1 ? (scene.nFrames - 1) / scene.fps : 0;
  if (clip) {
    const action = mixer.clipAction(clip);
    action.setLoop(THREE.LoopOnce);
    action.clampWhenFinished = true;
    action.play();
  }
  frameScene(v, gltf);

  const audio = document.getElementById("audio");
  const slider = document.getElementById("scrub");
  const button = document.getElementById("play");
  const label = document.getElementById("time");
  slider.max = String(duration);
  let playing = false;
  let clock = 0; // animation time (s)
  let started = 0;
  const hasAudio = Boolean(scene.audio);
  if (hasAudio) audio.src = scene.audio;

  function show(t) {
    clock = Math.min(Math.max(t, 0), duration);
    mixer.setTime(clock);
    slider.value = String(clock);
    label.textContent = `${clock.toFixed(2)} / ${duration.toFixed(2)} s`;
    v.renderer.render(v.world, v.camera);
  }
  function seek(t) {
    show(t);
    if (hasAudio) audio.currentTime = Math.max(clock - scene.audioOffset, 0);
    started = performance.now() / 1000 - clock;
  }
  async function play() {
    if (clock >= duration) seek(0);
    playing = true;
    button.textContent = "Pause";
    started = performance.now() / 1000 - clock;
    if (hasAudio && clock >= scene.audioOffset) {
      audio.currentTime = clock - scene.audioOffset;
      try { await audio.play(); } catch (e) { console.warn("audio:", e.message); }
    }
  }
  function pause() {
    playing = false;
    button.textContent = "Play";
    if (hasAudio) audio.pause();
  }
  function tick() {
    if (playing) {
      // the audio is the clock while it plays, the page's own clock before it starts and
      // whenever the audio's is not to be trusted: while it seeks, or far from the page's
      // (a slow machine that has just started the audio reports 0 for a while: the face
      // jumped back to the start)
      let t = performance.now() / 1000 - started;
      if (hasAudio && !audio.paused && !audio.seeking) {
        const heard = audio.currentTime + scene.audioOffset;
        if (Math.abs(heard - t) < AUDIO_TRUST_S) {
          t = heard;
          started = performance.now() / 1000 - t;
        } else {
          audio.currentTime = Math.max(t - scene.audioOffset, 0);  // bring the sound along
        }
      }
      if (hasAudio && audio.paused && t >= scene.audioOffset && t < duration) {
        audio.currentTime = t - scene.audioOffset;
        audio.play().catch(() => {});
      }
      show(t);
      if (t >= duration) pause();
    } else {
      v.renderer.render(v.world, v.camera);
    }
    requestAnimationFrame(tick);
  }
  button.addEventListener("click", () => (playing ? pause() : play()));
  slider.addEventListener("input", () => { pause(); seek(Number(slider.value)); });
  v.controls.addEventListener("change", () => v.renderer.render(v.world, v.camera));
  seek(0);
  requestAnimationFrame(tick);

  window.facelibPlayer = {
    duration, fps: scene.fps, nFrames: scene.nFrames, play, pause, seek,
    time: () => clock,
    isPlaying: () => playing,
    // a camera given as facelib's renderer holds it: a (4, 4) row-major pose, radians
    setCamera(pose, yfov, near, far) {
      v.controls.enabled = false;
      const m = new THREE.Matrix4().set(...pose.flat());
      v.camera.matrixAutoUpdate = false;
      v.camera.matrix.copy(m);
      v.camera.matrixWorld.copy(m);
      v.camera.matrixWorldInverse.copy(m).invert();
      v.camera.fov = THREE.MathUtils.radToDeg(yfov);
      v.camera.near = near;
      v.camera.far = far;
      v.camera.aspect = v.canvas.width / v.canvas.height;
      v.camera.updateProjectionMatrix();
      v.renderer.render(v.world, v.camera);
    },
  };
  document.body.dataset.ready = "1";
}

main().catch((e) => {
  document.body.dataset.error = String(e && e.stack ? e.stack : e);
  console.error(e);
});
