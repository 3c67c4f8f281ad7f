// The script of the page weft export writes for a .html output (exchange/src/preview_html.cpp
// inlines it): the fitted material's glTF, embedded as base64 in #weft-glb, on its cushion and
// draped cloth under three.js's RoomEnvironment, orbitable with the mouse. It renders on demand
// (on load, on orbit, on resize) rather than every frame: the scene is still, and a headless
// browser taking a screenshot then finds the frame drawn once the load has settled.
import * as THREE from 'three';
import { GLTFLoader } from 'weft/GLTFLoader';
import { OrbitControls } from 'weft/OrbitControls';
import { RoomEnvironment } from 'weft/RoomEnvironment';

const status = document.getElementById('weft-status');
// Say on the page what went wrong: a preview that silently stays blank tells its reader nothing.
function fail(error) {
  status.textContent = 'The preview could not be shown: ' + error;
  document.body.dataset.weftPreview = 'failed';
}

try {
  const view = document.getElementById('weft-view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(view.clientWidth, view.clientHeight);
  // No tone mapping: a diffuse surface under the room's light shows about its base colour, so
  // the colours on screen can be read against the fitted ones printed below.
  renderer.toneMapping = THREE.NoToneMapping;
  view.appendChild(renderer.domElement);

  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0.8, 0.8, 0.8);
  const pmrem = new THREE.PMREMGenerator(renderer);
  scene.environment = pmrem.fromScene(new RoomEnvironment(renderer), 0.04).texture;

  const camera = new THREE.PerspectiveCamera(35, view.clientWidth / view.clientHeight, 0.05, 50);
  camera.position.set(0.3, 1.3, 2.6);
  const controls = new OrbitControls(camera, renderer.domElement);
  controls.target.set(-0.1, 0.3, 0);
  const render = () => renderer.render(scene, camera);
  controls.addEventListener('change', render);
  controls.update();
  window.addEventListener('resize', () => {
    camera.aspect = view.clientWidth / view.clientHeight;
    camera.updateProjectionMatrix();
    renderer.setSize(view.clientWidth, view.clientHeight);
    render();
  });

  const text = document.getElementById('weft-glb').textContent.trim();
  const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  new GLTFLoader().parse(bytes.buffer, '', (gltf) => {
    scene.add(gltf.scene);
    render();
    status.textContent = 'Drag to orbit, scroll to zoom, right-drag to pan.';
    document.body.dataset.weftPreview = 'rendered';
  }, fail);
} catch (error) {
  fail(error);
}
