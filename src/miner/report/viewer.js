// MINER report viewer: draws the scene in <script id="miner-scene"> with three.js and
// reports what happened in #miner-status (data-state = "drawn" with the count of pixels
// that differ from the background, or "error: ..."), which the headless-browser test reads.
(function () {
  'use strict';
  var status = document.getElementById('miner-status');
  function report(state, pixels) {
    status.setAttribute('data-state', state);
    if (pixels !== undefined) status.setAttribute('data-pixels', String(pixels));
    status.textContent = state === 'drawn' ? '' : state;
  }
  window.addEventListener('error', function (e) { report('error: ' + e.message); });
  try {
    var scene_data = JSON.parse(document.getElementById('miner-scene').textContent);
    var host = document.getElementById('view3d');
    var width = host.clientWidth, height = host.clientHeight;
    var background = 0xf7f7f7;
    var renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(1);
    renderer.setSize(width, height);
    renderer.setClearColor(background, 1);
    host.appendChild(renderer.domElement);

    var scene = new THREE.Scene();
    scene.add(new THREE.AmbientLight(0xffffff, 0.6));
    var sun = new THREE.DirectionalLight(0xffffff, 0.5);
    sun.position.set(1, 2, 3);
    scene.add(sun);

    var bmin = new THREE.Vector3().fromArray(scene_data.bounds.min);
    var bmax = new THREE.Vector3().fromArray(scene_data.bounds.max);
    var centre = bmin.clone().add(bmax).multiplyScalar(0.5);
    var extent = bmax.clone().sub(bmin);
    var diag = extent.length();

    var camera = new THREE.PerspectiveCamera(45, width / height, diag / 1000, diag * 10);
    camera.up.set(0, 0, 1);  // ENU: z is up
    camera.position.copy(centre).add(new THREE.Vector3(-0.45 * diag, -0.7 * diag, 0.55 * diag));
    var controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.copy(centre);
    controls.update();

    var layers = {};
    function layer(name) {
      var g = new THREE.Group();
      scene.add(g);
      layers[name] = g;
      return g;
    }
    // Bounds as a wire box.
    var bounds_box = new THREE.Box3(bmin, bmax);
    layer('bounds').add(new THREE.Box3Helper(bounds_box, 0x999999));

    // Obstacles: translucent boxes with dark edges.
    var obstacles = layer('map');
    var obstacle_material = new THREE.MeshLambertMaterial({color: 0x8c8c8c, transparent: true, opacity: 0.35,
                                                           depthWrite: false});
    var edge_material = new THREE.LineBasicMaterial({color: 0x444444});
    scene_data.obstacles.forEach(function (b) {
      var size = [b[3] - b[0], b[4] - b[1], b[5] - b[2]];
      var geometry = new THREE.BoxBufferGeometry(size[0], size[1], size[2]);
      var mesh = new THREE.Mesh(geometry, obstacle_material);
      mesh.position.set((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
      obstacles.add(mesh);
      var edges = new THREE.LineSegments(new THREE.EdgesGeometry(geometry), edge_material);
      edges.position.copy(mesh.position);
      obstacles.add(edges);
    });

    // Heuristic region: one instanced cube per cell.
    if (scene_data.region && scene_data.region.centres.length > 0) {
      var c = scene_data.region.cell;
      var cube = new THREE.BoxBufferGeometry(c[0] * 0.9, c[1] * 0.9, c[2] * 0.9);
      var region_material = new THREE.MeshLambertMaterial({color: 0xf2b134, transparent: true, opacity: 0.25,
                                                           depthWrite: false});
      var n = scene_data.region.centres.length / 3;
      var cells = new THREE.InstancedMesh(cube, region_material, n);
      var m = new THREE.Matrix4();
      for (var i = 0; i < n; ++i) {
        m.makeTranslation(scene_data.region.centres[3 * i], scene_data.region.centres[3 * i + 1],
                          scene_data.region.centres[3 * i + 2]);
        cells.setMatrixAt(i, m);
      }
      // r111 culls an InstancedMesh by its one cube's bounds at the origin: never cull it.
      cells.frustumCulled = false;
      layer('region').add(cells);
    }

    function polyline(flat, color, name) {
      if (!flat || flat.length < 6) return;
      var g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(flat, 3));
      // Drawn last and over everything (transparent pass, highest render order, no depth
      // test), so the translucent map, region and tree never hide the curves.
      var line = new THREE.Line(g, new THREE.LineBasicMaterial({color: color, depthTest: false, transparent: true,
                                                                opacity: 1.0}));
      line.renderOrder = 10;
      layer(name).add(line);
    }
    if (scene_data.tree && scene_data.tree.length >= 6) {
      var tg = new THREE.BufferGeometry();
      tg.setAttribute('position', new THREE.Float32BufferAttribute(scene_data.tree, 3));
      layer('tree').add(new THREE.LineSegments(tg, new THREE.LineBasicMaterial({color: 0x6baed6, transparent: true,
                                                                                opacity: 0.3})));
    }
    polyline(scene_data.planned_path, 0x9467bd, 'planned path');
    polyline(scene_data.path, 0xd62728, 'path');
    polyline(scene_data.trajectory, 0x1f77b4, 'trajectory');
    polyline(scene_data.flown, 0x2ca02c, 'flown');

    var marker = new THREE.SphereBufferGeometry(Math.max(scene_data.radius, diag / 200), 16, 12);
    var ends = layer('start / goal');
    [[scene_data.start, 0x2ca02c], [scene_data.goal, 0xd62728]].forEach(function (p) {
      var s = new THREE.Mesh(marker, new THREE.MeshLambertMaterial({color: p[1], depthTest: false, transparent: true,
                                                                    opacity: 1.0}));
      s.renderOrder = 11;
      s.position.fromArray(p[0]);
      ends.add(s);
    });

    // Layer toggles.
    var toggles = document.getElementById('layers');
    Object.keys(layers).forEach(function (name) {
      var label = document.createElement('label');
      var box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = true;
      box.addEventListener('change', function () { layers[name].visible = box.checked; render(); });
      label.appendChild(box);
      label.appendChild(document.createTextNode(' ' + name + ' '));
      toggles.appendChild(label);
    });

    function render() { renderer.render(scene, camera); }
    controls.addEventListener('change', render);
    render();

    // Count the pixels that differ from the background: the test's evidence that the
    // view drew something.
    var gl = renderer.getContext();
    var pixels = new Uint8Array(width * height * 4);
    gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, pixels);
    var bg = [(background >> 16) & 255, (background >> 8) & 255, background & 255];
    var drawn = 0;
    for (var p = 0; p < pixels.length; p += 4)
      if (Math.abs(pixels[p] - bg[0]) + Math.abs(pixels[p + 1] - bg[1]) + Math.abs(pixels[p + 2] - bg[2]) > 24) ++drawn;
    report(drawn > 0 ? 'drawn' : 'error: the 3D view drew nothing', drawn);
  } catch (e) {
    report('error: ' + (e && e.message ? e.message : String(e)));
  }
})();
