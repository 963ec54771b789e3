// MINER report viewer. Draws the scene in <script id="miner-scene"> and the thinned flight
// log in <script id="miner-flight"> as a 3D view (three.js) or, where the browser gives no
// WebGL context, as a 2D top view (x-y) on a canvas; runs the playback slider (vehicle
// marker, time, read-out, the plots' time cursor). It reports what happened in
// #miner-status, which the headless-browser test (ci/check_report.py) reads:
//   data-state   "drawn" or "error: ..."
//   data-view    "3d" or "top"
//   data-pixels  pixels of the view that differ from its background
//   data-t       the playback time (s, 2 decimals); data-marker: the vehicle marker's x,y,z (m)
//   data-layers  the layer names; data-flown-colours: distinct colours of the flown path
//   data-grid-step the ground grid's spacing (m); data-not-depth-tested: objects drawn over
//                everything (the playback marker aside), 0 by design
//   data-view-rect, data-plots: where the view and every plot lie on the page (x,y,w,h px)
// The URL's fragment may set the playback time: report.html#t=4.5.
(function () {
  'use strict';
  var status = document.getElementById('miner-status');
  function report(state, attributes) {
    status.setAttribute('data-state', state);
    Object.keys(attributes || {}).forEach(function (k) { status.setAttribute('data-' + k, String(attributes[k])); });
    status.textContent = state === 'drawn' ? '' : state;
  }
  window.addEventListener('error', function (e) { report('error: ' + e.message); });

  var BACKGROUND = 0xf7f7f7;
  var BG = [(BACKGROUND >> 16) & 255, (BACKGROUND >> 8) & 255, BACKGROUND & 255];
  var COLORS = {planned: 0x9467bd, path: 0xd62728, trajectory: 0x1f77b4, tree: 0x6baed6, region: 0xf2b134,
                obstacle: 0x8c8c8c, start: 0x2ca02c, goal: 0xd62728, reference: 0x1f77b4};
  function css(hex, alpha) {
    var r = (hex >> 16) & 255, g = (hex >> 8) & 255, b = hex & 255;
    return alpha === undefined ? 'rgb(' + r + ',' + g + ',' + b + ')' : 'rgba(' + r + ',' + g + ',' + b + ',' + alpha + ')';
  }
  // 1-2-5 x 10^k at or above v.
  function nice(v) {
    if (!(v > 0)) return 1;
    var mag = Math.pow(10, Math.floor(Math.log10(v)));
    var steps = [1, 2, 5, 10];
    for (var i = 0; i < steps.length; ++i) if (steps[i] * mag >= v - 1e-12) return steps[i] * mag;
    return 10 * mag;
  }
  function label(v) { return String(Math.round(v * 1000) / 1000); }
  // Tracking-error colour scale (the legend's gradient): green, yellow, red over [0, max].
  var STOPS = [[0x1a, 0x98, 0x50], [0xfe, 0xe0, 0x8b], [0xd7, 0x30, 0x27]];
  function errorRgb(e, max) {
    var u = Math.max(0, Math.min(1, max > 0 ? e / max : 0)) * (STOPS.length - 1);
    var k = Math.min(STOPS.length - 2, Math.floor(u)), f = u - k;
    return [0, 1, 2].map(function (c) { return Math.round(STOPS[k][c] + f * (STOPS[k + 1][c] - STOPS[k][c])); });
  }

  try {
    var sd = JSON.parse(document.getElementById('miner-scene').textContent);
    var flight_el = document.getElementById('miner-flight');
    var fd = flight_el ? JSON.parse(flight_el.textContent) : {columns: {t: []}, events: []};
    var C = fd.columns, T = C.t || [], n = T.length;
    var has = function (names) { return names.every(function (c) { return C[c] && C[c].length === n; }); };
    var xyz = function (prefix, i) { return [C[prefix + 'x'][i], C[prefix + 'y'][i], C[prefix + 'z'][i]]; };
    var hasTruth = n > 0 && has(['true_x', 'true_y', 'true_z']);
    var hasRef = n > 0 && has(['ref_x', 'ref_y', 'ref_z']);
    var hasAttitude = has(['true_roll', 'true_pitch', 'true_yaw']);
    // Tracking error |p - p_ref| of every flown sample, and the scale's top (1-2-5).
    var error = [], errorMax = 0;
    for (var i = 0; i < n; ++i) {
      var e = 0;
      if (hasTruth && hasRef) {
        var p = xyz('true_', i), r = xyz('ref_', i);
        e = Math.sqrt((p[0] - r[0]) * (p[0] - r[0]) + (p[1] - r[1]) * (p[1] - r[1]) + (p[2] - r[2]) * (p[2] - r[2]));
      }
      error.push(e);
      errorMax = Math.max(errorMax, e);
    }
    var errorTop = nice(errorMax);
    var scaleMax = document.getElementById('error-scale-max');
    if (scaleMax) scaleMax.textContent = label(errorTop);
    var flownColours = {};
    error.forEach(function (v) { flownColours[errorRgb(v, errorTop).join(',')] = true; });

    var bmin = sd.bounds.min, bmax = sd.bounds.max;
    var ext = [bmax[0] - bmin[0], bmax[1] - bmin[1], bmax[2] - bmin[2]];
    var diag = Math.sqrt(ext[0] * ext[0] + ext[1] * ext[1] + ext[2] * ext[2]);
    var gridStep = nice(Math.max(ext[0], ext[1]) / 12);
    var host = document.getElementById('view3d');
    var overlay = document.getElementById('view-overlay');

    var hasWebGL = function () {
      try {
        var probe = document.createElement('canvas');
        return !!(window.WebGLRenderingContext && (probe.getContext('webgl') || probe.getContext('experimental-webgl')));
      } catch (err) { return false; }
    };

    var tEnd = n > 0 ? T[n - 1] : 0;
    var indexAt = function (t) {
      var lo = 0, hi = n - 1;
      if (n === 0) return -1;
      while (lo < hi) {
        var mid = (lo + hi + 1) >> 1;
        if (T[mid] <= t + 1e-9) lo = mid; else hi = mid - 1;
      }
      return lo;
    };
    var view = null, why = 'WebGL is not available in this browser';
    if (typeof THREE !== 'undefined' && hasWebGL()) {
      try { view = make3d(); } catch (err) { view = null; why = 'the 3D view failed (' + (err && err.message) + ')'; }
    }
    if (!view) view = makeTop(why);

    // Layer toggles.
    var toggles = document.getElementById('layers');
    view.layerNames.forEach(function (name) {
      var lbl = document.createElement('label');
      var box = document.createElement('input');
      box.type = 'checkbox';
      box.checked = view.visible(name);
      box.setAttribute('data-layer', name);
      box.addEventListener('change', function () { view.setVisible(name, box.checked); view.render(); });
      lbl.appendChild(box);
      lbl.appendChild(document.createTextNode(' ' + name + ' '));
      toggles.appendChild(lbl);
    });

    // Playback: the slider's time moves the vehicle marker, the read-out and the plots' cursor.
    var slider = document.getElementById('playback-slider');
    var timeLabel = document.getElementById('playback-time');
    var readout = document.getElementById('playback-readout');
    var play = document.getElementById('playback-play');
    var current = 0, markerAt = null, markerT = null;
    var cursors = [];
    Array.prototype.forEach.call(document.querySelectorAll('svg.plot[data-px0]'), function (svg) {
      var line = svg.querySelector('line.cursor');
      if (line) cursors.push({line: line, x0: +svg.getAttribute('data-x0'), x1: +svg.getAttribute('data-x1'),
                              px0: +svg.getAttribute('data-px0'), px1: +svg.getAttribute('data-px1')});
    });
    var setTime = function (t) {
      t = Math.max(0, Math.min(tEnd, t));
      current = t;
      var k = indexAt(t);
      timeLabel.textContent = 't = ' + t.toFixed(2) + ' s';
      if (slider && Math.abs(+slider.value - t) > 1e-9) slider.value = String(t);
      cursors.forEach(function (c) {
        var x = c.px0 + (t - c.x0) / (c.x1 - c.x0 || 1) * (c.px1 - c.px0);
        c.line.setAttribute('x1', x.toFixed(1));
        c.line.setAttribute('x2', x.toFixed(1));
        c.line.setAttribute('visibility', t >= c.x0 && t <= c.x1 ? 'visible' : 'hidden');
      });
      if (k < 0 || !hasTruth) return;
      markerAt = xyz('true_', k);
      markerT = T[k];
      var text = 'position (' + markerAt.map(function (v) { return v.toFixed(2); }).join(', ') + ') m';
      if (has(['true_vx', 'true_vy', 'true_vz'])) {
        var v = xyz('true_v', k);
        text += ', speed ' + Math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).toFixed(2) + ' m/s';
      }
      if (hasRef) text += ', tracking error ' + (100 * error[k]).toFixed(1) + ' cm';
      if (hasAttitude)
        text += ', roll/pitch/yaw ' + ['true_roll', 'true_pitch', 'true_yaw'].map(function (c) {
          return (C[c][k] * 180 / Math.PI).toFixed(1);
        }).join(' / ') + ' deg';
      var active = (fd.events || []).filter(function (ev) { return t >= ev.t0 && t <= ev.t1; });
      text += active.length ? ', events: ' + active.map(function (ev) { return ev.name; }).join(', ') : ', no event';
      readout.textContent = text;
      view.setMarker(k);
      view.render();
    };
    if (slider) slider.addEventListener('input', function () { stop(); setTime(+slider.value); });
    var playing = false, last = 0;
    var stop = function () { playing = false; if (play) play.textContent = 'play'; };
    var frame = function (now) {
      if (!playing) return;
      if (last) setTime(current + (now - last) / 1000);
      last = now;
      if (current >= tEnd) { stop(); return; }
      window.requestAnimationFrame(frame);
    };
    if (play) play.addEventListener('click', function () {
      if (playing) { stop(); return; }
      if (current >= tEnd) setTime(0);
      playing = true;
      last = 0;
      play.textContent = 'pause';
      window.requestAnimationFrame(frame);
    });
    var m = /(?:^#|&)t=([0-9.]+)/.exec(window.location.hash);
    setTime(m ? parseFloat(m[1]) : 0);
    view.render();

    var rect = function (el) {
      var b = el.getBoundingClientRect();
      return [b.left + window.scrollX, b.top + window.scrollY, b.width, b.height].map(Math.round).join(',');
    };
    var plots = Array.prototype.map.call(document.querySelectorAll('svg.plot[id]'), function (svg) {
      return svg.id + ':' + rect(svg);
    }).join(';');
    var drawn = view.countPixels();
    report(drawn > 0 ? 'drawn' : 'error: the ' + view.kind + ' view drew nothing', {
      view: view.kind, pixels: drawn, t: current.toFixed(2),
      marker: markerAt ? markerAt.map(function (v) { return v.toFixed(3); }).join(',') : '',
      'marker-t': markerT === null ? '' : markerT.toFixed(3),
      'grid-step': gridStep, 'not-depth-tested': view.undepthed,
      layers: view.layerNames.join(','), 'flown-colours': Object.keys(flownColours).length,
      'error-max': errorMax.toFixed(4), 'view-rect': rect(view.canvas), plots: plots});
  } catch (e) {
    report('error: ' + (e && e.message ? e.message : String(e)));
  }

  // ---------------------------------------------------------------- the 3D view (three.js)
  function make3d() {
    var width = host.clientWidth, height = host.clientHeight;
    var renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
    renderer.setPixelRatio(1);
    renderer.setSize(width, height);
    renderer.setClearColor(BACKGROUND, 1);
    host.insertBefore(renderer.domElement, host.firstChild);

    var scene = new THREE.Scene();
    scene.add(new THREE.AmbientLight(0xffffff, 0.6));
    var sun = new THREE.DirectionalLight(0xffffff, 0.5);
    sun.position.set(1, 2, 3);
    scene.add(sun);
    var vmin = new THREE.Vector3().fromArray(bmin), vmax = new THREE.Vector3().fromArray(bmax);
    var centre = vmin.clone().add(vmax).multiplyScalar(0.5);
    centre.z = vmin.z + 0.25 * ext[2];
    var camera = new THREE.PerspectiveCamera(40, width / height, diag / 1000, diag * 10);
    camera.up.set(0, 0, 1);  // ENU: z is up
    // From the south-west, above: the whole map and the grid's labels in the frame.
    // The target a little toward the near corner, so that the grid's labels stay in the frame.
    centre.x -= 0.06 * ext[0];
    centre.y -= 0.06 * ext[1];
    camera.position.copy(centre).add(new THREE.Vector3(-0.6 * diag, -0.92 * diag, 0.8 * diag));
    var controls = new THREE.OrbitControls(camera, renderer.domElement);
    controls.target.copy(centre);
    controls.update();

    var layers = {}, names = [];
    function layer(name, visible) {
      if (!layers[name]) {
        var g = new THREE.Group();
        g.visible = visible !== false;
        scene.add(g);
        layers[name] = g;
        names.push(name);
      }
      return layers[name];
    }
    // Text that always faces the camera, `size` metres tall.
    function textSprite(text, color, size) {
      var canvas = document.createElement('canvas');
      var ctx = canvas.getContext('2d');
      ctx.font = 'bold 40px sans-serif';
      canvas.width = Math.ceil(ctx.measureText(text).width) + 8;
      canvas.height = 52;
      ctx.font = 'bold 40px sans-serif';
      ctx.fillStyle = color;
      ctx.textBaseline = 'middle';
      ctx.fillText(text, 4, 26);
      var texture = new THREE.CanvasTexture(canvas);
      texture.minFilter = THREE.LinearFilter;
      var sprite = new THREE.Sprite(new THREE.SpriteMaterial({map: texture, transparent: true, depthWrite: false}));
      sprite.scale.set(size * canvas.width / canvas.height, size, 1);
      return sprite;
    }
    function lineGeometry(flat) {
      var g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(flat, 3));
      return g;
    }

    // Ground grid at the map's floor, labelled in metres, and the axes at its lower corner.
    var gx0 = Math.floor(bmin[0] / gridStep) * gridStep, gx1 = Math.ceil(bmax[0] / gridStep) * gridStep;
    var gy0 = Math.floor(bmin[1] / gridStep) * gridStep, gy1 = Math.ceil(bmax[1] / gridStep) * gridStep;
    var floor = bmin[2], grid = [], x, y;
    for (x = gx0; x <= gx1 + 1e-9; x += gridStep) grid.push(x, gy0, floor, x, gy1, floor);
    for (y = gy0; y <= gy1 + 1e-9; y += gridStep) grid.push(gx0, y, floor, gx1, y, floor);
    var ground = layer('grid and axes');
    ground.add(new THREE.LineSegments(lineGeometry(grid), new THREE.LineBasicMaterial({color: 0xc8c8c8})));
    var textSize = gridStep * 0.32;
    var every = Math.max(1, Math.ceil(((gx1 - gx0) / gridStep) / 12));
    var k;
    for (k = 0, x = gx0; x <= gx1 + 1e-9; x += gridStep, ++k) {
      if (k % every) continue;
      var sx = textSprite(label(x), '#555', textSize);
      sx.position.set(x, gy0 - 0.45 * gridStep, floor);
      ground.add(sx);
    }
    for (k = 0, y = gy0; y <= gy1 + 1e-9; y += gridStep, ++k) {
      if (k % every) continue;
      var sy = textSprite(label(y), '#555', textSize);
      sy.position.set(gx0 - 0.55 * gridStep, y, floor);
      ground.add(sy);
    }
    var origin = new THREE.Vector3(gx0, gy0, floor), axisLength = 2 * gridStep;
    [[new THREE.Vector3(1, 0, 0), 0xd62728, 'x'], [new THREE.Vector3(0, 1, 0), 0x2ca02c, 'y'],
     [new THREE.Vector3(0, 0, 1), 0x1f77b4, 'z']].forEach(function (a) {
      // A solid arrow (a shaft and a cone): 1-px lines are too thin to see from afar.
      var turn = new THREE.Quaternion().setFromUnitVectors(new THREE.Vector3(0, 1, 0), a[0]);
      var material = new THREE.MeshBasicMaterial({color: a[1]});
      var shaft = new THREE.Mesh(new THREE.CylinderBufferGeometry(0.025 * gridStep, 0.025 * gridStep,
                                                                   axisLength - 0.25 * gridStep, 8), material);
      shaft.quaternion.copy(turn);
      shaft.position.copy(origin).addScaledVector(a[0], (axisLength - 0.25 * gridStep) / 2);
      var cone = new THREE.Mesh(new THREE.ConeBufferGeometry(0.08 * gridStep, 0.25 * gridStep, 12), material);
      cone.quaternion.copy(turn);
      cone.position.copy(origin).addScaledVector(a[0], axisLength - 0.125 * gridStep);
      ground.add(shaft);
      ground.add(cone);
      var s = textSprite(a[2] + ' (m)', css(a[1]), textSize * 1.2);
      // Beside the arrow's tip, off the other axes' labels.
      s.position.copy(origin).addScaledVector(a[0], axisLength + 0.4 * gridStep);
      if (a[2] === 'y') s.position.x -= 0.6 * gridStep;
      if (a[2] === 'z') s.position.add(new THREE.Vector3(0.5 * gridStep, -0.5 * gridStep, 0));
      ground.add(s);
    });
    ground.add(new THREE.Box3Helper(new THREE.Box3(vmin, vmax), 0x999999));
    overlay.innerHTML = 'Grid: <b>' + label(gridStep) + ' m</b> squares on the floor (z = ' + label(floor) +
                        ' m); axes x (red), y (green), z (blue) from (' + label(gx0) + ', ' + label(gy0) + ', ' +
                        label(floor) + ') m, ' + label(axisLength) + ' m long.';

    // Obstacles: translucent boxes that write depth, so what lies behind them is dimmed and
    // what lies in front is not (every line and tube is depth-tested).
    var obstacles = layer('map');
    var obstacleMaterial = new THREE.MeshLambertMaterial({color: COLORS.obstacle, transparent: true, opacity: 0.45});
    var edgeMaterial = new THREE.LineBasicMaterial({color: 0x555555});
    sd.obstacles.forEach(function (b) {
      var geometry = new THREE.BoxBufferGeometry(b[3] - b[0], b[4] - b[1], b[5] - b[2]);
      var mesh = new THREE.Mesh(geometry, obstacleMaterial);
      mesh.position.set((b[0] + b[3]) / 2, (b[1] + b[4]) / 2, (b[2] + b[5]) / 2);
      obstacles.add(mesh);
      var edges = new THREE.LineSegments(new THREE.EdgesGeometry(geometry), edgeMaterial);
      edges.position.copy(mesh.position);
      obstacles.add(edges);
    });

    if (sd.region && sd.region.centres.length > 0) {
      var c = sd.region.cell;
      var cube = new THREE.BoxBufferGeometry(c[0] * 0.9, c[1] * 0.9, c[2] * 0.9);
      var regionMaterial = new THREE.MeshLambertMaterial({color: COLORS.region, transparent: true, opacity: 0.18,
                                                          depthWrite: false});
      var count = sd.region.centres.length / 3;
      var cells = new THREE.InstancedMesh(cube, regionMaterial, count);
      var mat = new THREE.Matrix4();
      for (var q = 0; q < count; ++q) {
        mat.makeTranslation(sd.region.centres[3 * q], sd.region.centres[3 * q + 1], sd.region.centres[3 * q + 2]);
        cells.setMatrixAt(q, mat);
      }
      cells.frustumCulled = false;  // r111 culls an InstancedMesh by its one cube at the origin
      layer('region', false).add(cells);
    }
    if (sd.tree && sd.tree.length >= 6)
      layer('RRT* tree', false).add(new THREE.LineSegments(lineGeometry(sd.tree), new THREE.LineBasicMaterial({
        color: COLORS.tree, transparent: true, opacity: 0.35, depthWrite: false})));

    // A tube along a polyline (parallel-transported frames), coloured per point or plain.
    function tube(points, radius, colours) {
      var count = points.length, sides = 8, pos = [], col = [], index = [];
      var prevN = null, prevT = new THREE.Vector3(1, 0, 0);
      for (var i = 0; i < count; ++i) {
        var a = points[Math.max(0, i - 1)], b = points[Math.min(count - 1, i + 1)];
        var t = new THREE.Vector3().subVectors(b, a);
        if (t.lengthSq() < 1e-12) t.copy(prevT); else t.normalize();
        var nrm;
        if (!prevN) {
          nrm = Math.abs(t.z) < 0.9 ? new THREE.Vector3(0, 0, 1) : new THREE.Vector3(1, 0, 0);
          nrm.sub(t.clone().multiplyScalar(nrm.dot(t))).normalize();
        } else {
          nrm = prevN.clone().sub(t.clone().multiplyScalar(prevN.dot(t)));
          if (nrm.lengthSq() < 1e-12) nrm.copy(prevN); else nrm.normalize();
        }
        var bin = new THREE.Vector3().crossVectors(t, nrm);
        for (var s = 0; s < sides; ++s) {
          var ang = 2 * Math.PI * s / sides;
          var d = nrm.clone().multiplyScalar(Math.cos(ang)).addScaledVector(bin, Math.sin(ang));
          pos.push(points[i].x + radius * d.x, points[i].y + radius * d.y, points[i].z + radius * d.z);
          if (colours) col.push(colours[i][0] / 255, colours[i][1] / 255, colours[i][2] / 255);
          if (i > 0) {
            var s1 = (s + 1) % sides, base = (i - 1) * sides;
            index.push(base + s, base + s1, base + sides + s, base + s1, base + sides + s1, base + sides + s);
          }
        }
        prevN = nrm;
        prevT = t;
      }
      var g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
      if (colours) g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
      g.setIndex(index);
      g.computeVertexNormals();
      return g;
    }
    function points(flat) {
      var out = [];
      for (var i = 0; i + 2 < flat.length; i += 3) out.push(new THREE.Vector3(flat[i], flat[i + 1], flat[i + 2]));
      return out;
    }
    var tubeRadius = Math.max(diag / 150, 0.02);
    // The trajectory: a wide translucent tube under the flown path.
    if (sd.trajectory && sd.trajectory.length >= 6) {
      var trajectory = new THREE.Mesh(tube(points(sd.trajectory), tubeRadius, null), new THREE.MeshLambertMaterial({
        color: COLORS.trajectory, transparent: true, opacity: 0.2}));
      trajectory.renderOrder = -1;  // before the obstacles in the transparent pass
      layer('trajectory').add(trajectory);
    }
    // Planned path dashed over the repaired path (solid): where they agree, both show.
    if (sd.planned_path && sd.planned_path.length >= 6) {
      var planned = new THREE.Line(lineGeometry(sd.planned_path), new THREE.LineDashedMaterial({
        color: COLORS.planned, dashSize: diag / 80, gapSize: diag / 160}));
      planned.computeLineDistances();
      planned.renderOrder = 1;
      layer('planned path').add(planned);
    }
    if (sd.path && sd.path.length >= 6)
      layer('repaired path').add(new THREE.Line(lineGeometry(sd.path), new THREE.LineBasicMaterial({color: COLORS.path})));
    // The flown path: a thin tube coloured by tracking error.
    if (hasTruth && n >= 2) {
      var flownPoints = [], colours = [];
      for (var f = 0; f < n; ++f) {
        flownPoints.push(new THREE.Vector3().fromArray(xyz('true_', f)));
        colours.push(errorRgb(error[f], errorTop));
      }
      layer('flown').add(new THREE.Mesh(tube(flownPoints, tubeRadius * 0.5, colours), new THREE.MeshLambertMaterial({
        vertexColors: THREE.VertexColors})));
    }
    var markerSize = Math.max(1.5 * sd.radius, diag / 60);
    var ends = layer('start / goal');
    var ball = new THREE.SphereBufferGeometry(markerSize * 0.6, 16, 12);
    [[sd.start, COLORS.start], [sd.goal, COLORS.goal]].forEach(function (p) {
      var s = new THREE.Mesh(ball, new THREE.MeshLambertMaterial({color: p[1]}));
      s.position.fromArray(p[0]);
      ends.add(s);
    });
    // Events: a small diamond where each began.
    var eventLayer = layer('events');
    var diamond = new THREE.OctahedronBufferGeometry(markerSize * 0.5);
    (fd.events || []).forEach(function (ev) {
      var k0 = indexAt(ev.t0);
      if (k0 < 0 || !hasTruth) return;
      var d = new THREE.Mesh(diamond, new THREE.MeshLambertMaterial({color: new THREE.Color(ev.color)}));
      d.position.fromArray(xyz('true_', k0));
      eventLayer.add(d);
    });
    // The vehicle at the slider's time: an X frame (front arm red) turned by its attitude,
    // drawn over everything; a ring marks the reference there.
    var vehicle = new THREE.Group(), onTop = function (color) {
      return new THREE.MeshBasicMaterial({color: color, depthTest: false, transparent: true});
    };
    var arm = new THREE.BoxBufferGeometry(2 * markerSize, markerSize * 0.16, markerSize * 0.08);
    [Math.PI / 4, -Math.PI / 4].forEach(function (a) {
      var m = new THREE.Mesh(arm, onTop(0x222222));
      m.rotation.z = a;
      vehicle.add(m);
    });
    var nose = new THREE.Mesh(new THREE.SphereBufferGeometry(markerSize * 0.22, 12, 8), onTop(0xd62728));
    nose.position.set(markerSize * 0.9, 0, 0);
    vehicle.add(nose);
    vehicle.add(new THREE.Mesh(new THREE.SphereBufferGeometry(markerSize * 0.28, 12, 8), onTop(0x222222)));
    vehicle.children.forEach(function (c) { c.renderOrder = 20; });
    var refMarker = new THREE.Mesh(new THREE.TorusBufferGeometry(markerSize * 0.7, markerSize * 0.08, 6, 24),
                                   onTop(COLORS.reference));
    refMarker.renderOrder = 19;
    var playback = layer('vehicle');
    playback.add(vehicle);
    playback.add(refMarker);
    vehicle.visible = refMarker.visible = false;

    // Everything but the playback marker is depth-tested: the test reads this count.
    var undepthed = 0;
    names.forEach(function (name) {
      if (name !== 'vehicle')
        layers[name].traverse(function (o) { if (o.material && o.material.depthTest === false) ++undepthed; });
    });

    function render() { renderer.render(scene, camera); }
    controls.addEventListener('change', render);
    return {
      kind: '3d', canvas: renderer.domElement, layerNames: names, undepthed: undepthed,
      visible: function (name) { return layers[name].visible; },
      setVisible: function (name, on) { layers[name].visible = on; },
      render: render,
      setMarker: function (i) {
        vehicle.visible = true;
        vehicle.position.fromArray(xyz('true_', i));
        if (hasAttitude) vehicle.rotation.set(C.true_roll[i], C.true_pitch[i], C.true_yaw[i], 'ZYX');
        refMarker.visible = hasRef;
        if (hasRef) refMarker.position.fromArray(xyz('ref_', i));
      },
      countPixels: function () {
        render();
        var gl = renderer.getContext();
        var px = new Uint8Array(width * height * 4);
        gl.readPixels(0, 0, width, height, gl.RGBA, gl.UNSIGNED_BYTE, px);
        return countDrawn(px);
      }
    };
  }

  function countDrawn(px) {
    var drawn = 0;
    for (var p = 0; p < px.length; p += 4)
      if (Math.abs(px[p] - BG[0]) + Math.abs(px[p + 1] - BG[1]) + Math.abs(px[p + 2] - BG[2]) > 24) ++drawn;
    return drawn;
  }

  // ---------------------------------------------------------------- the 2D top view (x-y)
  function makeTop(why) {
    var width = host.clientWidth, height = host.clientHeight;
    var canvas = document.createElement('canvas');
    canvas.width = width;
    canvas.height = height;
    host.insertBefore(canvas, host.firstChild);
    var ctx = canvas.getContext('2d');
    var margin = 48;
    var scale = Math.min((width - 2 * margin) / (ext[0] || 1), (height - 2 * margin) / (ext[1] || 1));
    var ox = (width - scale * ext[0]) / 2, oy = (height + scale * ext[1]) / 2;
    function X(x) { return ox + (x - bmin[0]) * scale; }
    function Y(y) { return oy - (y - bmin[1]) * scale; }
    var names = ['grid and axes', 'map', 'region', 'RRT* tree', 'trajectory', 'planned path', 'repaired path',
                 'flown', 'start / goal', 'events', 'vehicle'];
    var shown = {};
    names.forEach(function (nm) { shown[nm] = nm !== 'RRT* tree' && nm !== 'region'; });
    var marker = -1;
    overlay.innerHTML = '<b>Top view (x-y)</b>: ' + why + '. Grid: <b>' + label(gridStep) + ' m</b> squares.';
    function poly(flat, stride) {
      ctx.beginPath();
      for (var i = 0; i + 1 < flat.length; i += stride) {
        if (i === 0) ctx.moveTo(X(flat[i]), Y(flat[i + 1])); else ctx.lineTo(X(flat[i]), Y(flat[i + 1]));
      }
      ctx.stroke();
    }
    function render() {
      ctx.setLineDash([]);
      ctx.fillStyle = css(BACKGROUND);
      ctx.fillRect(0, 0, width, height);
      var x, y, k;
      if (shown['grid and axes']) {
        var gx0 = Math.floor(bmin[0] / gridStep) * gridStep, gx1 = Math.ceil(bmax[0] / gridStep) * gridStep;
        var gy0 = Math.floor(bmin[1] / gridStep) * gridStep, gy1 = Math.ceil(bmax[1] / gridStep) * gridStep;
        ctx.strokeStyle = '#d0d0d0';
        ctx.lineWidth = 1;
        ctx.font = '11px sans-serif';
        ctx.fillStyle = '#555';
        ctx.textAlign = 'center';
        for (x = gx0; x <= gx1 + 1e-9; x += gridStep) {
          ctx.beginPath(); ctx.moveTo(X(x), Y(gy0)); ctx.lineTo(X(x), Y(gy1)); ctx.stroke();
          ctx.fillText(label(x), X(x), Y(gy0) + 14);
        }
        ctx.textAlign = 'right';
        for (y = gy0; y <= gy1 + 1e-9; y += gridStep) {
          ctx.beginPath(); ctx.moveTo(X(gx0), Y(y)); ctx.lineTo(X(gx1), Y(y)); ctx.stroke();
          ctx.fillText(label(y), X(gx0) - 4, Y(y) + 4);
        }
        ctx.strokeStyle = '#999';
        ctx.strokeRect(X(bmin[0]), Y(bmax[1]), ext[0] * scale, ext[1] * scale);
        // Axes from the grid's corner, and a scale bar.
        ctx.lineWidth = 2;
        ctx.font = 'bold 12px sans-serif';
        [[1, 0, '#d62728', 'x'], [0, 1, '#2ca02c', 'y']].forEach(function (a) {
          var x1 = X(gx0 + a[0] * 2 * gridStep), y1 = Y(gy0 + a[1] * 2 * gridStep);
          ctx.strokeStyle = ctx.fillStyle = a[2];
          ctx.beginPath(); ctx.moveTo(X(gx0), Y(gy0)); ctx.lineTo(x1, y1); ctx.stroke();
          ctx.textAlign = 'center';
          ctx.fillText(a[3] + ' (m)', x1 + a[0] * 18, y1 - a[1] * 8 + 4);
        });
        var barX = width - margin - gridStep * scale, barY = height - 14;
        ctx.strokeStyle = ctx.fillStyle = '#222';
        ctx.beginPath(); ctx.moveTo(barX, barY); ctx.lineTo(barX + gridStep * scale, barY); ctx.stroke();
        ctx.beginPath(); ctx.moveTo(barX, barY - 4); ctx.lineTo(barX, barY + 4);
        ctx.moveTo(barX + gridStep * scale, barY - 4); ctx.lineTo(barX + gridStep * scale, barY + 4); ctx.stroke();
        ctx.textAlign = 'right';
        ctx.fillText(label(gridStep) + ' m', barX - 6, barY + 4);
      }
      if (shown.region && sd.region) {
        ctx.fillStyle = css(COLORS.region, 0.08);
        var c = sd.region.cell;
        for (k = 0; k + 2 < sd.region.centres.length; k += 3)
          ctx.fillRect(X(sd.region.centres[k] - c[0] * 0.45), Y(sd.region.centres[k + 1] + c[1] * 0.45),
                       c[0] * 0.9 * scale, c[1] * 0.9 * scale);
      }
      if (shown.map) {
        ctx.lineWidth = 1;
        ctx.fillStyle = css(COLORS.obstacle, 0.45);
        ctx.strokeStyle = '#555';
        sd.obstacles.forEach(function (b) {
          ctx.fillRect(X(b[0]), Y(b[4]), (b[3] - b[0]) * scale, (b[4] - b[1]) * scale);
          ctx.strokeRect(X(b[0]), Y(b[4]), (b[3] - b[0]) * scale, (b[4] - b[1]) * scale);
        });
      }
      if (shown['RRT* tree'] && sd.tree) {
        ctx.strokeStyle = css(COLORS.tree, 0.4);
        ctx.lineWidth = 1;
        ctx.beginPath();
        for (k = 0; k + 5 < sd.tree.length; k += 6) {
          ctx.moveTo(X(sd.tree[k]), Y(sd.tree[k + 1]));
          ctx.lineTo(X(sd.tree[k + 3]), Y(sd.tree[k + 4]));
        }
        ctx.stroke();
      }
      ctx.lineCap = ctx.lineJoin = 'round';
      if (shown.trajectory && sd.trajectory) {
        ctx.strokeStyle = css(COLORS.trajectory, 0.3);
        ctx.lineWidth = 9;
        poly(sd.trajectory, 3);
      }
      if (shown['repaired path'] && sd.path) {
        ctx.strokeStyle = css(COLORS.path);
        ctx.lineWidth = 1;
        poly(sd.path, 3);
      }
      if (shown['planned path'] && sd.planned_path) {
        ctx.strokeStyle = css(COLORS.planned);
        ctx.lineWidth = 1.5;
        ctx.setLineDash([8, 5]);
        poly(sd.planned_path, 3);
        ctx.setLineDash([]);
      }
      if (shown.flown && hasTruth) {
        ctx.lineWidth = 2.5;
        for (k = 1; k < n; ++k) {
          ctx.strokeStyle = 'rgb(' + errorRgb(error[k], errorTop).join(',') + ')';
          ctx.beginPath();
          ctx.moveTo(X(C.true_x[k - 1]), Y(C.true_y[k - 1]));
          ctx.lineTo(X(C.true_x[k]), Y(C.true_y[k]));
          ctx.stroke();
        }
      }
      function dot(p, color, r) {
        ctx.fillStyle = color;
        ctx.beginPath(); ctx.arc(X(p[0]), Y(p[1]), r, 0, 2 * Math.PI); ctx.fill();
      }
      if (shown['start / goal']) {
        dot(sd.start, css(COLORS.start), 6);
        dot(sd.goal, css(COLORS.goal), 6);
      }
      if (shown.events && hasTruth)
        (fd.events || []).forEach(function (ev) {
          var k0 = indexAt(ev.t0);
          if (k0 < 0) return;
          var px = X(C.true_x[k0]), py = Y(C.true_y[k0]);
          ctx.fillStyle = ev.color;
          ctx.beginPath(); ctx.moveTo(px, py - 6); ctx.lineTo(px + 6, py); ctx.lineTo(px, py + 6); ctx.lineTo(px - 6, py);
          ctx.fill();
        });
      if (shown.vehicle && marker >= 0) {
        if (hasRef) {
          ctx.strokeStyle = css(COLORS.reference);
          ctx.lineWidth = 2;
          ctx.beginPath(); ctx.arc(X(C.ref_x[marker]), Y(C.ref_y[marker]), 8, 0, 2 * Math.PI); ctx.stroke();
        }
        // A triangle pointing along the yaw.
        var yaw = hasAttitude ? C.true_yaw[marker] : 0, cx = X(C.true_x[marker]), cy = Y(C.true_y[marker]);
        ctx.fillStyle = '#222';
        ctx.beginPath();
        [[12, 0], [-7, 6], [-4, 0], [-7, -6]].forEach(function (q, j) {
          var px = cx + q[0] * Math.cos(yaw) - q[1] * Math.sin(yaw), py = cy - (q[0] * Math.sin(yaw) + q[1] * Math.cos(yaw));
          if (j === 0) ctx.moveTo(px, py); else ctx.lineTo(px, py);
        });
        ctx.closePath();
        ctx.fill();
      }
    }
    return {
      kind: 'top', canvas: canvas, layerNames: names, undepthed: 0,
      visible: function (name) { return shown[name]; },
      setVisible: function (name, on) { shown[name] = on; },
      render: render,
      setMarker: function (i) { marker = i; },
      countPixels: function () {
        render();
        return countDrawn(ctx.getImageData(0, 0, width, height).data);
      }
    };
  }
})();
