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

  // three.js has no KHR_materials_diffuse_transmission: the material's own shader gets its term,
  // the glTF's diffuse BTDF lit by the environment's irradiance from behind the surface, mixed
  // with the diffuse reflection by the factor (the extension's base = mix(diffuse_brdf,
  // diffuse_btdf, factor); the BTDF's Fresnel weight is left out).
  const showDiffuseTransmission = (gltf) => {
    const defs = gltf.parser.json.materials || [];
    gltf.scene.traverse((object) => {
      if (!object.isMesh) return;
      const found = gltf.parser.associations.get(object.material);
      const def = found && defs[found.materials];
      const ext = def && def.extensions && def.extensions.KHR_materials_diffuse_transmission;
      if (!ext || object.material.userData.weftDiffuseTransmission) return;
      const factor = ext.diffuseTransmissionFactor ?? 0;
      const colour = ext.diffuseTransmissionColorFactor ?? [1, 1, 1];
      object.material.userData.weftDiffuseTransmission = true;
      object.material.onBeforeCompile = (shader) => {
        // The chunk of three.js 0.160's physical shader after which the lights are summed; the
        // page says whether it was found (a three.js that moved it would show the cloth opaque).
        const chunk = '#include <lights_fragment_end>';
        const found = shader.fragmentShader.includes(chunk);
        document.body.dataset.weftDiffuseTransmission = found ? 'shown' : 'not shown';
        shader.uniforms.weftTransmission = { value: factor };
        shader.uniforms.weftTransmissionColour = { value: new THREE.Vector3(...colour) };
        shader.fragmentShader =
          'uniform float weftTransmission;\nuniform vec3 weftTransmissionColour;\n' +
          shader.fragmentShader.replace(chunk, `${chunk}
#if defined( USE_ENVMAP ) && defined( ENVMAP_TYPE_CUBE_UV )
  reflectedLight.indirectDiffuse = mix( reflectedLight.indirectDiffuse,
    weftTransmissionColour * RECIPROCAL_PI * getIBLIrradiance( - geometryNormal ), weftTransmission );
#endif`);
      };
      object.material.needsUpdate = true;
    });
  };

  const text = document.getElementById('weft-glb').textContent.trim();
  const bytes = Uint8Array.from(atob(text), (c) => c.charCodeAt(0));
  new GLTFLoader().parse(bytes.buffer, '', (gltf) => {
    showDiffuseTransmission(gltf);
    scene.add(gltf.scene);
    render();
    status.textContent = 'Drag to orbit, scroll to zoom, right-drag to pan.';
    document.body.dataset.weftPreview = 'rendered';
  }, fail);
} catch (error) {
  fail(error);
}
