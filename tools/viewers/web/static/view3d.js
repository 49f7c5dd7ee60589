// The 3D view: the robot from its joint angles with the field, the ball and the cameras' view cones;
// drag to orbit, wheel to zoom. The program computes the links' poses with its own kinematic model
// (RobotLinks, from JointSensorData and TorsoPose); this page only places them. Field frame in
// metres, z up. Drawn on demand (at most 15 times a second), never while hidden.

import * as THREE from "three";
import { OrbitControls } from "./vendor/OrbitControls.js";

const M = 0.001;
const FPS = 15;
const CONE_LENGTH = { top: 1.5, bottom: 0.8 }; // m shown of each camera's view
const CONE_COLOUR = { top: 0xffe066, bottom: 0x66ccff };

export function view3d(body, connection, state, panel) {
  body.classList.add("view3d-body");
  const seen = state.view3d = { links: {}, message: null, frames: 0, drawn: 0, webgl: true };
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xdfe6ee);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x445544, 2.5));
  const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
  camera.up.set(0, 0, 1);
  camera.position.set(-1.6, -1.6, 1.2);
  let renderer = null;
  try {
    renderer = new THREE.WebGLRenderer({ antialias: true });
    body.append(renderer.domElement);
  } catch (error) {
    seen.webgl = false;
    body.textContent = "this browser offers no WebGL: the 3D view cannot be drawn here";
    console.warn(error);
  }
  const controls = renderer ? new OrbitControls(camera, renderer.domElement) : null;
  controls?.target.set(0, 0, 0.25);
  controls?.addEventListener("change", schedule);

  const fieldGroup = new THREE.Group();
  scene.add(fieldGroup);
  const robot = new THREE.Group(); // the robot frame on the field: RobotPose
  robot.name = "robot";
  scene.add(robot);
  const linkMaterial = new THREE.MeshLambertMaterial({ color: 0x2b59c3 });
  const bones = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x1d2330 }));
  robot.add(bones);
  const cones = {};
  for (const name of ["top", "bottom"]) {
    const cone = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: CONE_COLOUR[name] }));
    cone.matrixAutoUpdate = false;
    cone.name = `camera_${name}`;
    robot.add(cone);
    cones[name] = cone;
  }
  const ball = new THREE.Mesh(new THREE.SphereGeometry(0.05, 16, 12), new THREE.MeshLambertMaterial({ color: 0xff8c00 }));
  ball.visible = false;
  robot.add(ball);

  connection.on("open", async () => {
    try { drawField(fieldGroup, await connection.json("field:geometry")); } catch (error) { console.warn(error.message); }
    schedule();
  });
  panel.follow("RobotLinks", { hz: FPS }, (message) => { place(message.value); seen.message = message.value; seen.frame = message.frame; seen.frames += 1; schedule(); });
  panel.follow("RobotPose", { hz: 5 }, (message) => {
    const pose = message.value;
    robot.position.set(pose.x * M, pose.y * M, 0);
    robot.rotation.set(0, 0, pose.rotation);
    if (controls && !seen.aimed) { controls.target.set(pose.x * M, pose.y * M, 0.25); camera.position.set(pose.x * M - 1.6, pose.y * M - 1.6, 1.2); seen.aimed = true; }
    schedule();
  });
  panel.follow("BallModel", { hz: 10 }, (message) => {
    const value = message.value;
    ball.visible = value.valid;
    ball.position.set(value.x * M, value.y * M, 0.05);
    schedule();
  });

  function place(value) {
    const positions = [];
    for (const [name, link] of Object.entries(value.links)) {
      let mesh = seen.links[name];
      if (!mesh) {
        mesh = seen.links[name] = new THREE.Mesh(new THREE.BoxGeometry(0.04, 0.04, 0.04), linkMaterial);
        mesh.name = name;
        mesh.matrixAutoUpdate = false;
        robot.add(mesh);
      }
      mesh.matrix.copy(matrix(link));
      const parent = value.links[link.parent];
      if (parent) positions.push(...parent.translation.map((v) => v * M), ...link.translation.map((v) => v * M));
    }
    bones.geometry.setAttribute("position", new THREE.Float32BufferAttribute(positions, 3));
    bones.geometry.computeBoundingSphere();
    for (const [name, pose] of Object.entries(value.cameras)) {
      if (!cones[name]) continue;
      cones[name].matrix.copy(matrix(pose));
      if (!cones[name].geometry.getAttribute("position")) cones[name].geometry = coneGeometry(value.fov, CONE_LENGTH[name]);
    }
  }

  function matrix(pose) {
    const [r, t] = [pose.rotation, pose.translation];
    return new THREE.Matrix4().set(r[0][0], r[0][1], r[0][2], t[0] * M, r[1][0], r[1][1], r[1][2], t[1] * M,
      r[2][0], r[2][1], r[2][2], t[2] * M, 0, 0, 0, 1);
  }

  let queued = false, drawnAt = 0;
  function schedule() {
    if (queued || !renderer) return;
    queued = true;
    const wait = Math.max(0, drawnAt + 1000 / FPS - performance.now());
    setTimeout(() => requestAnimationFrame(() => { queued = false; drawnAt = performance.now(); draw(); }), wait);
  }
  new ResizeObserver(schedule).observe(body);
  panel.onShow = schedule;

  function draw() {
    if (!panel.shown()) return;
    const width = body.clientWidth, height = body.clientHeight;
    if (width < 10 || height < 10) return;
    if (renderer.domElement.width !== Math.round(width * devicePixelRatio) || renderer.domElement.height !== Math.round(height * devicePixelRatio)) {
      renderer.setPixelRatio(devicePixelRatio);
      renderer.setSize(width, height);
      camera.aspect = width / height;
      camera.updateProjectionMatrix();
    }
    renderer.render(scene, camera);
    seen.drawn += 1;
  }
  // for tests and the curious: each link's pose in the robot frame as the scene holds it (column-major)
  seen.linkMatrix = (name) => { robot.updateMatrixWorld(true); return seen.links[name]?.matrix.elements.slice(); };
  seen.robotMatrix = () => { robot.updateMatrixWorld(true); return robot.matrixWorld.elements.slice(); };
}

// A pyramid from the camera along its x axis (optical axis; y left, z up in the image).
function coneGeometry(fov, length) {
  const y = Math.tan(fov.horizontal / 2) * length, z = Math.tan(fov.vertical / 2) * length;
  const corners = [[length, y, z], [length, -y, z], [length, -y, -z], [length, y, -z]];
  const points = [];
  corners.forEach((corner, i) => { points.push(0, 0, 0, ...corner, ...corner, ...corners[(i + 1) % 4]); });
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(points, 3));
  return geometry;
}

function drawField(group, g) {
  group.clear();
  const carpet = new THREE.Mesh(new THREE.PlaneGeometry((g.length + 2 * g.border) * M, (g.width + 2 * g.border) * M),
    new THREE.MeshLambertMaterial({ color: 0x2f8a3a }));
  group.add(carpet);
  const points = [];
  for (const [x1, y1, x2, y2] of g.lines) points.push(x1 * M, y1 * M, 0.002, x2 * M, y2 * M, 0.002);
  for (let i = 0; i < 48; i++) {
    const a = (i / 48) * Math.PI * 2, b = ((i + 1) / 48) * Math.PI * 2, r = g.circle.radius * M;
    points.push(r * Math.cos(a), r * Math.sin(a), 0.002, r * Math.cos(b), r * Math.sin(b), 0.002);
  }
  const lines = new THREE.BufferGeometry();
  lines.setAttribute("position", new THREE.Float32BufferAttribute(points, 3));
  group.add(new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ color: 0xffffff })));
  for (const [x, y] of g.posts) {
    const post = new THREE.Mesh(new THREE.CylinderGeometry(g.post_radius * M, g.post_radius * M, 0.8, 12), new THREE.MeshLambertMaterial({ color: 0xffffff }));
    post.rotation.x = Math.PI / 2;
    post.position.set(x * M, y * M, 0.4);
    group.add(post);
  }
}
