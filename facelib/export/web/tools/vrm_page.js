// Bundled by vrm_check.mjs and run in headless chromium: loads a .vrm with @pixiv/three-vrm
// and a .vrma with @pixiv/three-vrm-animation (both given as base64 in window.FACELIB_VRM),
// plays the animation on the avatar with three.js's AnimationMixer, and reports, per asked
// time, what the avatar shows: every expression's weight, the head bone's normalized
// rotation, the look-at's yaw and pitch, and the morph target influences of every part mesh
// (facelib writes one mesh per part, named for it: "skin", "eye_l" ...).
import * as THREE from "three";
import { GLTFLoader } from "three/examples/jsm/loaders/GLTFLoader.js";
import { VRMLoaderPlugin } from "@pixiv/three-vrm";
import { VRMAnimationLoaderPlugin, createVRMAnimationClip } from "@pixiv/three-vrm-animation";

function bytes(base64) {
  const text = atob(base64);
  const out = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
  return out.buffer;
}

async function parse(base64, plugin) {
  const loader = new GLTFLoader();
  loader.register(plugin);
  return loader.parseAsync(bytes(base64), "");
}

async function main() {
  const job = window.FACELIB_VRM;
  const avatar = await parse(job.vrm, (parser) => new VRMLoaderPlugin(parser));
  const vrm = avatar.userData.vrm;
  const report = {
    meta: vrm.meta.metaVersion,
    bones: Object.keys(vrm.humanoid.humanBones).filter((b) => vrm.humanoid.getRawBoneNode(b)),
    expressions: vrm.expressionManager.expressions.map((e) => e.expressionName),
    frames: [],
  };
  if (job.vrma) {
    const motion = await parse(job.vrma, (parser) => new VRMAnimationLoaderPlugin(parser));
    const clip = createVRMAnimationClip(motion.userData.vrmAnimations[0], vrm);
    report.duration = clip.duration;
    report.tracks = clip.tracks.map((t) => t.name);
    const mixer = new THREE.AnimationMixer(vrm.scene);
    mixer.clipAction(clip).play();
    const meshes = [];
    vrm.scene.traverse((o) => { if (o.isMesh && o.morphTargetInfluences) meshes.push(o); });
    for (const t of job.times) {
      mixer.setTime(t);
      vrm.update(0);
      const weights = {};
      for (const name of report.expressions) weights[name] = vrm.expressionManager.getValue(name);
      report.frames.push({
        t,
        weights,
        head: vrm.humanoid.getNormalizedBoneNode("head").quaternion.toArray(),
        look: [vrm.lookAt.yaw, vrm.lookAt.pitch],
        influences: Object.fromEntries(meshes.map((m) => [m.name, Array.from(m.morphTargetInfluences)])),
      });
    }
  }
  if (job.shoot != null) {
    const canvas = document.createElement("canvas");
    canvas.width = 480; canvas.height = 480; canvas.id = "view";
    document.body.appendChild(canvas);
    const renderer = new THREE.WebGLRenderer({ canvas, antialias: true });
    const scene = new THREE.Scene();
    scene.background = new THREE.Color(0x303030);
    scene.add(vrm.scene, new THREE.AmbientLight(0xffffff, 1.2));
    const sun = new THREE.DirectionalLight(0xffffff, 2.0);
    sun.position.set(0.5, 1, 2);
    scene.add(sun);
    const head = new THREE.Vector3();
    vrm.humanoid.getRawBoneNode("head").getWorldPosition(head);
    const camera = new THREE.PerspectiveCamera(25, 1, 0.01, 10);
    camera.position.set(head.x, head.y + 0.05, head.z + 0.75);
    camera.lookAt(head.x, head.y + 0.05, head.z);
    renderer.render(scene, camera);
  }
  return report;
}

main().then((r) => { window.FACELIB_RESULT = r; },
            (e) => { window.FACELIB_RESULT = { error: String(e && e.stack || e) }; });
