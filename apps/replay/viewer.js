// SPDX-License-Identifier: BSD-3-Clause
// The replay page's own code (docs/guides/replay.md): places what the scene gives at the instant
// shown, interpolating between samples (positions linearly, orientations by slerp), and
// reports what it shows in #mcopt-state so that a test can check it.
(function () {
  'use strict';
  const errors = [];
  window.addEventListener('error', (e) => errors.push(String(e.message)));
  const consoleError = console.error.bind(console);
  console.error = (...args) => { errors.push(args.map(String).join(' ')); consoleError(...args); };

  const started = performance.now();
  const scene = JSON.parse(document.getElementById('mcopt-scene').textContent);
  const FORCE_SCALE = 1 / 1000;  // m per N, as the legend says
  const times = scene.time;
  // The timeline covers the motion and, for a throw, the ball's flight to the target's height
  // (the robot at rest in its last pose meanwhile).
  const duration = Math.max(times[times.length - 1], scene.ball ? scene.ball.release_time + scene.ball.flight_time : 0);

  // Z up, as the robot's world frame.
  THREE.Object3D.DefaultUp.set(0, 0, 1);
  const view = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.appendChild(renderer.domElement);
  const world = new THREE.Scene();
  world.background = new THREE.Color(0xeef1f5);
  world.add(new THREE.HemisphereLight(0xffffff, 0x667788, 0.75));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.set(2, -3, 5);
  world.add(sun);

  // The floor: the reference contact's height at the first sample.
  const grid = new THREE.GridHelper(6, 30, 0x8899aa, 0xc8d0d8);
  grid.rotation.x = Math.PI / 2;
  grid.position.z = scene.floor_height;
  world.add(grid);

  function material(rgba) {
    return new THREE.MeshLambertMaterial({
      color: new THREE.Color(rgba[0], rgba[1], rgba[2]), transparent: rgba[3] < 1, opacity: rgba[3] });
  }
  function shapeMesh(shape) {
    let geometry;
    if (shape.kind === 'box') geometry = new THREE.BoxBufferGeometry(shape.size[0], shape.size[1], shape.size[2]);
    else if (shape.kind === 'sphere') geometry = new THREE.SphereBufferGeometry(shape.size[0], 20, 14);
    else {
      // URDF cylinders lie along z, three.js's along y.
      geometry = new THREE.CylinderBufferGeometry(shape.size[0], shape.size[0], shape.size[1], 20);
      geometry.rotateX(Math.PI / 2);
    }
    const mesh = new THREE.Mesh(geometry, material(shape.rgba));
    setPose(mesh, shape.pose);
    return mesh;
  }
  function setPose(object, p) {
    object.position.set(p[0], p[1], p[2]);
    object.quaternion.set(p[3], p[4], p[5], p[6]);
  }

  const bodies = scene.bodies.map((body) => {
    const group = new THREE.Group();
    group.name = body.name;
    body.shapes.forEach((shape) => group.add(shapeMesh(shape)));
    world.add(group);
    return { group, poses: body.poses };
  });

  // Forces, centres of pressure and the centre of mass lie inside the feet and the trunk:
  // drawn over the robot, not hidden by it.
  function drawnOnTop(object) {
    object.renderOrder = 10;
    object.traverse((o) => { if (o.material) { o.material.depthTest = false; o.material.transparent = true; } });
  }

  const contactColours = [0xd62728, 0x1f77b4, 0x2ca02c, 0x9467bd, 0xff7f0e];
  const contacts = scene.contacts.map((contact, c) => {
    const colour = contactColours[c % contactColours.length];
    const [x0, x1, y0, y1] = contact.rectangle;
    const outline = new THREE.BufferGeometry().setFromPoints(
      [[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]].map(([x, y]) => new THREE.Vector3(x, y, 0.001)));
    const frame = new THREE.Group();
    frame.add(new THREE.Line(outline, new THREE.LineBasicMaterial({ color: colour })));
    const patch = new THREE.Mesh(new THREE.PlaneBufferGeometry(x1 - x0, y1 - y0),
      new THREE.MeshBasicMaterial({ color: colour, transparent: true, opacity: 0.25, side: THREE.DoubleSide }));
    patch.position.set((x0 + x1) / 2, (y0 + y1) / 2, 0.0005);
    frame.add(patch);
    world.add(frame);
    const arrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.1, colour, 0.06, 0.035);
    const cop = new THREE.Mesh(new THREE.SphereBufferGeometry(0.015, 12, 8), new THREE.MeshBasicMaterial({ color: colour }));
    drawnOnTop(arrow);
    drawnOnTop(cop);
    world.add(arrow, cop);
    return { contact, frame, arrow, cop };
  });

  const com = new THREE.Mesh(new THREE.SphereBufferGeometry(0.02, 16, 10), new THREE.MeshBasicMaterial({ color: 0x555555 }));
  drawnOnTop(com);
  world.add(com);

  // A throw's ball: in the hand up to the release, then on its flight p + v τ + ½ g τ² to the
  // target's height, where it stays; its path and the target drawn throughout.
  const ball = scene.ball;
  let ballMesh = null;
  if (ball) {
    ballMesh = new THREE.Mesh(new THREE.SphereGeometry(0.035, 20, 14), material([0.95, 0.55, 0.1, 1]));
    world.add(ballMesh);
    const path = [];
    for (let i = 0; i <= 60; i += 1) path.push(new THREE.Vector3(...ballInFlight(ball.flight_time * i / 60)));
    world.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(path),
                             new THREE.LineDashedMaterial({ color: 0xe08020, dashSize: 0.05, gapSize: 0.03 })).computeLineDistances());
    const target = new THREE.Mesh(new THREE.RingGeometry(0.04, 0.07, 32), new THREE.MeshBasicMaterial({ color: 0xd02020, side: THREE.DoubleSide }));
    target.position.set(...ball.target);
    target.position.z += 0.002;
    world.add(target);
  }
  function ballInFlight(tau) {
    return [0, 1, 2].map((i) => ball.position[i] + ball.velocity[i] * tau + 0.5 * scene.gravity[i] * tau * tau);
  }

  const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  {
    // Looking at the robot's first centre of mass from its front right.
    const c = scene.center_of_mass[0];
    controls.target.set(c[0], c[1], c[2]);
    camera.position.set(c[0] + 2.3, c[1] - 1.7, c[2] + 0.6);
    controls.update();
  }

  // The samples around t and the weight of the later one.
  function bracket(t) {
    let lo = 0, hi = times.length - 1;
    if (t <= times[0]) return [0, 0, 0];
    if (t >= times[hi]) return [hi, hi, 0];
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid;
    }
    return [lo, hi, (t - times[lo]) / (times[hi] - times[lo])];
  }
  const qa = new THREE.Quaternion(), qb = new THREE.Quaternion();
  function placeAt(object, poses, k0, k1, w) {
    const a = poses[k0], b = poses[k1];
    object.position.set(a[0] + w * (b[0] - a[0]), a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2]));
    qa.set(a[3], a[4], a[5], a[6]);
    qb.set(b[3], b[4], b[5], b[6]);
    THREE.Quaternion.slerp(qa, qb, object.quaternion, w);
  }
  function lerp3(a, b, w) { return [0, 1, 2].map((i) => a[i] + w * (b[i] - a[i])); }

  function show(t) {
    const [k0, k1, w] = bracket(t);
    bodies.forEach((body) => placeAt(body.group, body.poses, k0, k1, w));
    contacts.forEach(({ contact, frame, arrow, cop }) => {
      placeAt(frame, contact.poses, k0, k1, w);
      const k = w < 0.5 ? k0 : k1;  // a contact is on or off at a sample, not in between
      frame.visible = contact.active[k];
      const f0 = contact.force[k0], f1 = contact.force[k1];
      const force = f0 && f1 ? lerp3(f0, f1, w) : contact.force[k];
      const point = contact.cop[k0] && contact.cop[k1] ? lerp3(contact.cop[k0], contact.cop[k1], w) : contact.cop[k];
      const magnitude = force ? Math.hypot(force[0], force[1], force[2]) : 0;
      arrow.visible = cop.visible = Boolean(point) && magnitude > 1e-6;
      if (!arrow.visible) return;
      arrow.position.set(point[0], point[1], point[2]);
      arrow.setDirection(new THREE.Vector3(force[0], force[1], force[2]).normalize());
      arrow.setLength(Math.max(magnitude * FORCE_SCALE, 0.02), 0.06, 0.035);
      cop.position.set(point[0], point[1], point[2]);
    });
    const c = lerp3(scene.center_of_mass[k0], scene.center_of_mass[k1], w);
    com.position.set(c[0], c[1], c[2]);
    if (ball) {
      const p = t < ball.release_time ? lerp3(ball.carried[k0], ball.carried[k1], w)
                                      : ballInFlight(Math.min(t - ball.release_time, ball.flight_time));
      ballMesh.position.set(p[0], p[1], p[2]);
    }
  }

  // Playback.
  const playButton = document.getElementById('play');
  const slider = document.getElementById('slider');
  const clock = document.getElementById('clock');
  const speed = document.getElementById('speed');
  slider.max = String(duration);
  slider.step = String(duration / 1000);
  let t = 0, playing = true, last = null, frames = 0;

  function fragmentTime() {
    const match = /(?:^#|&)t=([0-9.eE+-]+)/.exec(window.location.hash);
    if (!match) return null;
    const value = Number(match[1]);
    return Number.isFinite(value) ? Math.min(Math.max(value, 0), duration) : null;
  }
  function setPlaying(on) {
    playing = on;
    last = null;
    playButton.textContent = on ? 'Pause' : 'Play';
    // Paused, the address names the instant shown: copy it to share this view.
    if (!on) history.replaceState(null, '', '#t=' + t.toFixed(3));
  }
  function openAtFragment() {
    const shared = fragmentTime();
    if (shared === null) return;
    t = shared;
    setPlaying(false);
  }
  playButton.addEventListener('click', () => setPlaying(!playing));
  slider.addEventListener('input', () => { t = Number(slider.value); if (playing) setPlaying(false); });
  window.addEventListener('hashchange', openAtFragment);
  openAtFragment();

  // mcopt verify's findings (verify.json beside the result): a tick on the timeline at every
  // instant where a check is broken; n / p pause at the next / previous one.
  const marks = scene.verify ? scene.verify.marks : [];
  const markList = document.getElementById('verify-marks');
  marks.forEach(({ time }) => {
    const option = document.createElement('option');
    option.value = String(time);
    markList.appendChild(option);
  });
  function markNear(t) {
    let best = null;
    marks.forEach(m => { if (best === null || Math.abs(m.time - t) < Math.abs(best.time - t)) best = m; });
    return best && Math.abs(best.time - t) <= duration / 200 ? best : null;
  }
  function verifyText() {
    if (!scene.verify) return '';
    if (!marks.length) return scene.verify.passed ? 'verify: every check holds between the samples' : 'verify: not verified (no instant marked)';
    const near = markNear(t);
    return `verify: broken at ${marks.length} instants (timeline ticks; n / p: next / previous)` +
      (near ? ` · here, t = ${near.time.toFixed(3)} s: ${near.checks.join(', ')}` : '');
  }
  window.addEventListener('keydown', event => {
    if (!marks.length || (event.key !== 'n' && event.key !== 'p')) return;
    const next = event.key === 'n' ? marks.find(m => m.time > t + 1e-9) : [...marks].reverse().find(m => m.time < t - 1e-9);
    if (!next) return;
    t = next.time;
    setPlaying(false);
  });

  document.getElementById('legend').textContent =
    `force arrows: 1 m per ${1 / FORCE_SCALE} N at the centre of pressure · grey dot: centre of mass`;
  document.getElementById('caption').textContent =
    `${scene.robot} · ${scene.scenario} · ${scene.status} · energy ${scene.energy.toFixed(4)} J`;

  // What is shown, for tests and scripts: the instant, the camera (so that a screenshot's
  // pixels can be matched with world points), every body's world pose and the centre of its
  // first shape.
  function report() {
    const size = renderer.getSize(new THREE.Vector2());
    const state = {
      t, playing, frames, errors, load_ms: loadMs, width: size.x, height: size.y,
      verify: scene.verify ? { passed: scene.verify.passed, marks: marks.map(m => m.time), shown: verifyText() } : null,
      camera: { position: camera.position.toArray(), target: controls.target.toArray(), up: camera.up.toArray(), fov_deg: camera.fov },
      bodies: {} };
    const position = new THREE.Vector3(), orientation = new THREE.Quaternion(), centre = new THREE.Vector3();
    bodies.forEach(({ group }) => {
      group.getWorldPosition(position);
      group.getWorldQuaternion(orientation);
      if (group.children.length) group.children[0].getWorldPosition(centre); else centre.copy(position);
      state.bodies[group.name] = {
        position: position.toArray(), quaternion_xyzw: orientation.toArray(), shape_centre: centre.toArray() };
    });
    if (ballMesh) state.ball = ballMesh.position.toArray();
    document.getElementById('mcopt-state').textContent = JSON.stringify(state);
  }

  function resize() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
  window.addEventListener('resize', resize);
  resize();

  let loadMs = null;
  function frame(now) {
    if (playing) {
      if (last !== null) t += (now - last) / 1000 * Number(speed.value);
      if (t > duration) t = 0;
      last = now;
    }
    slider.value = String(t);
    clock.textContent = `t = ${t.toFixed(3)} / ${duration.toFixed(3)} s`;
    document.getElementById('verify').textContent = verifyText();
    show(t);
    controls.update();
    renderer.render(world, camera);
    frames += 1;
    if (loadMs === null) loadMs = performance.now() - started;
    report();
    requestAnimationFrame(frame);
  }
  requestAnimationFrame(frame);
})();
