// report.html's script (inlined by vc::PlanToHtml, core/report/src/report_html.cc, after three.js
// r111 and its OrbitControls). Reads window.VC_REPORT_DATA (schema "vc.report/1", written there),
// fills the side panel and draws the plan with WebGL. Every string from the plan is inserted as
// text (textContent), never as HTML. After the first frame it sets window.vcReport.ready, the
// <body> data-* attributes and a title ending in " - ready" (an em dash) for headless tests;
// window.vcReport.markerScreenPosition(k) lets a test click station k's marker, and
// window.vcReport.showFloor(f) (or the URL's #floor=NAME) shows one floor.
(function () {
  'use strict';
  var D = window.VC_REPORT_DATA;
  // Drawn in the plan's local frame; every coordinate shown adds the frame's origin (the input's frame).
  var frame = D.frame_origin_m || [0, 0, 0];
  var R = window.vcReport;
  var body = document.body;

  // ---------- helpers ----------
  function bytes(base64) {
    var bin = atob(base64 || '');
    var out = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) out[i] = bin.charCodeAt(i);
    return out;
  }
  function el(tag, text, cls) {
    var e = document.createElement(tag);
    if (text !== undefined && text !== null) e.textContent = String(text);
    if (cls) e.className = cls;
    return e;
  }
  function num(v, digits) {
    return typeof v === 'number' && isFinite(v) ? v.toFixed(digits) : '\u2013';
  }
  function pct(v) { return typeof v === 'number' && isFinite(v) ? (100 * v).toFixed(1) + ' %' : '\u2013'; }
  function count(v) { return typeof v === 'number' ? v.toLocaleString('en-US') : '\u2013'; }
  function duration(s) {
    if (typeof s !== 'number' || !isFinite(s)) return '\u2013';
    var m = Math.round(s / 60);
    return m >= 60 ? Math.floor(m / 60) + ' h ' + (m % 60) + ' min' : m + ' min';
  }
  // The smallest of 1, 2, 5 x 10^k that is at least `atLeast` (> 0).
  function roundStep(atLeast) {
    var decade = Math.pow(10, Math.floor(Math.log(atLeast) / Math.LN10));
    var steps = [1, 2, 5, 10];
    for (var i = 0; i < steps.length; i++) if (steps[i] * decade >= atLeast * (1 - 1e-9)) return steps[i] * decade;
    return 10 * decade;
  }
  function fail(message) {
    R.errors.push(message);
    document.getElementById('errors').textContent = R.errors.join('\n');
    body.setAttribute('data-errors', String(R.errors.length));
  }

  // ---------- the side panel ----------
  var F = D.figures;
  var stations = D.stations;
  var P = D.points;
  var figures = document.getElementById('figures');
  function figure(name, value) {
    var tr = el('tr');
    tr.appendChild(el('td', name));
    tr.appendChild(el('td', value));
    figures.appendChild(tr);
  }
  figure('stations', stations.length + (F.fixed_stations ? ' (' + F.fixed_stations + ' fixed)' : ''));
  figure('coverage', pct(F.covered_fraction_of_coverable) + ' of coverable voxels (' + count(F.covered_voxels) +
         ' of ' + count(F.coverable_voxels) + '; ' + count(F.occupied_voxels) + ' occupied)');
  figure('visibility score (G)', num(F.global_visibility, 3) + ' of 1 (faces seen whole ' +
         pct(F.fully_visible_fraction) + ', in part ' + pct(F.partially_visible_fraction) + ')');
  figure('field time', duration(F.field_time_s.total) + ' (set-up ' + duration(F.field_time_s.setup) + ', scans ' +
         duration(F.field_time_s.scan) + ', walk ' + duration(F.field_time_s.walk) + ')');
  figure('walking route', num(F.route_length_m, 1) + ' m' + (F.route_parts > 1 ? ' in ' + F.route_parts + ' parts' : ''));
  figure('overlap links', D.edges.length + ' link(s) of overlap \u2265 ' + num(D.edge_min_overlap, 2) +
         (F.min_overlap > 0 ? (F.scan_graph_connected ? ', connected' : ', NOT connected') : ''));
  figure('voxel size', num(D.resolution_m, 3) + ' m (selection test: ' + D.selection_test + ')');
  figure('floors', D.floors.length + (D.keep_out.length ? ', ' + D.keep_out.length + ' keep-out zone(s)' : ''));

  var selectionNote = document.getElementById('selection');
  var tbody = document.querySelector('#stations tbody');
  var rows = [];
  function text(v) { return v === undefined || v === null ? '\u2013' : v; }
  stations.forEach(function (s, k) {
    var tr = el('tr');
    [s.number, text(s.name), text(s.floor), num(s.tripod_height_m, 2), text(s.walk_number),
     num(s.position[0] + frame[0], 2), num(s.position[1] + frame[1], 2), num(s.position[2] + frame[2], 2),
     num(s.global_visibility, 3), count(s.marginal_gain), s.sole_voxels === null ? '\u2013' : count(s.sole_voxels)]
        .forEach(function (v) { tr.appendChild(el('td', v)); });
    tr.title = s.fixed ? 'existing station' : 'new station';
    tr.addEventListener('click', function () { select(selected === k ? -1 : k); });
    tbody.appendChild(tr);
    rows.push(tr);
  });
  var warnings = document.getElementById('warnings');
  D.warnings.forEach(function (w) { warnings.appendChild(el('li', w)); });
  if (!D.warnings.length) warnings.appendChild(el('li', 'none'));
  var zoneList = document.getElementById('zones');
  // "x 1.00 to 2.00": a zone's extent along axis a (0, 1, 2) in the input's frame.
  function range(z, a) {
    return 'xyz'.charAt(a) + ' ' + num(z.min[a] + frame[a], 2) + ' to ' + num(z.max[a] + frame[a], 2);
  }
  D.keep_out.forEach(function (z) {
    var shape = z.shape === 'box' ? 'box' : 'polygon of ' + z.outline.length / 2 + ' corners within';
    zoneList.appendChild(el('li', 'zone ' + z.number + ', ' + shape + ' ' + range(z, 0) + ', ' + range(z, 1) + ', ' +
                                  range(z, 2) + ' m'));
  });
  if (!D.keep_out.length) zoneList.appendChild(el('li', 'none'));
  var shown = P.drawn === P.total ? 'all ' + count(P.total) + ' occupied voxels are drawn.'
      : count(P.drawn) + ' of ' + count(P.total) + ' occupied voxels are drawn (a fixed pseudo-random subset): ' +
        'at most ' + count(P.cap) + ' points keep the view smooth on a laptop.';
  document.getElementById('points-note').textContent = 'One point per voxel centre, coloured by its visibility ' +
      'score (the best of its 6 faces), as in visibility.ply; ' + shown;

  // ---------- the data ----------
  var n = P.drawn;
  var cells = new Uint16Array(bytes(P.xyz).buffer);
  var v = bytes(P.v);
  var sole = P.sole ? new Uint16Array(bytes(P.sole).buffer) : null;
  var palette = bytes(D.palette);
  if (cells.length !== 3 * n || v.length !== n || (sole && sole.length !== n) || palette.length !== 768) {
    fail('report data is inconsistent: ' + cells.length + ' coordinates, ' + v.length + ' values for ' + n + ' points');
    return;
  }
  // Everything is drawn relative to `origin` (the voxels' lowest corner), so float32 keeps
  // millimetres even in large world coordinates.
  var origin = P.origin;
  function local(p) { return new THREE.Vector3(p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]); }
  var positions = new Float32Array(3 * n);
  var box = new THREE.Box3();
  for (var i = 0; i < 3 * n; i++) positions[i] = cells[i] * P.step_m;
  for (i = 0; i < n; i++) box.expandByPoint(new THREE.Vector3(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]));
  stations.forEach(function (s) { box.expandByPoint(local(s.position)); });
  if (box.isEmpty()) box.set(new THREE.Vector3(0, 0, 0), new THREE.Vector3(1, 1, 1));
  var size = box.getSize(new THREE.Vector3());
  var extent = Math.max(size.x, size.y, size.z, 1);

  // ---------- legend and controls ----------
  var legend = document.getElementById('legend');
  var bar = document.createElement('canvas');
  bar.width = 255;
  bar.height = 1;
  var ctx = bar.getContext('2d');
  for (i = 1; i < 256; i++) {
    ctx.fillStyle = 'rgb(' + palette[3 * i] + ',' + palette[3 * i + 1] + ',' + palette[3 * i + 2] + ')';
    ctx.fillRect(i - 1, 0, 1, 1);
  }
  legend.appendChild(el('div', 'visibility score of a voxel (the best of its faces)'));
  legend.appendChild(bar);
  var ticks = el('div', null, 'ticks');
  ['0', '0.25', '0.5', '0.75', '1'].forEach(function (t) { ticks.appendChild(el('span', t)); });
  legend.appendChild(ticks);

  var controlsBox = document.getElementById('controls');
  function checkbox(text, checked, onChange) {
    var label = el('label');
    var input = document.createElement('input');
    input.type = 'checkbox';
    input.checked = checked;
    input.addEventListener('change', function () { onChange(input.checked); });
    label.appendChild(input);
    label.appendChild(document.createTextNode(' ' + text));
    controlsBox.appendChild(label);
    return label;
  }
  var unseenRed = false;
  var unseenLabel = checkbox('', false, function (on) { unseenRed = on; recolour(); });
  var swatch = el('span', null, 'swatch');
  unseenLabel.insertBefore(swatch, unseenLabel.lastChild);
  unseenLabel.lastChild.textContent = ' voxels no station sees (score 0) in red: ' + count(P.unseen_total) +
      (P.drawn === P.total ? '' : ' (' + count(P.unseen_drawn) + ' drawn)');

  // ---------- the 3D view ----------
  var view = document.getElementById('view');
  var renderer;
  try {
    renderer = new THREE.WebGLRenderer({antialias: true, preserveDrawingBuffer: true});
  } catch (e) {
    fail('WebGL is not available in this browser: ' + (e && e.message ? e.message : e));
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.setClearColor(0x24262b);
  renderer.localClippingEnabled = true;
  view.insertBefore(renderer.domElement, view.firstChild);
  var scene = new THREE.Scene();
  var camera = new THREE.PerspectiveCamera(50, 1, extent / 2000, extent * 50);
  camera.up.set(0, 0, 1);

  // Voxels: one point each, one voxel wide.
  var colours = new Float32Array(3 * n);
  var geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  var colourAttribute = new THREE.BufferAttribute(colours, 3);
  geometry.setAttribute('color', colourAttribute);
  var cut = new THREE.Plane(new THREE.Vector3(0, 0, -1), box.max.z + 1);
  // The shown floor's band of heights: `floorLow` hides what lies below it, `floorHigh` what lies
  // above it (the voxels' `cut` takes the lower of the slider and the band's top).
  var floorLow = new THREE.Plane(new THREE.Vector3(0, 0, 1), -(box.min.z - 1));
  var floorHigh = new THREE.Plane(new THREE.Vector3(0, 0, -1), box.max.z + 1);
  var floorClipping = [floorHigh, floorLow];
  // With size attenuation three.js draws a point `size` * (half the viewport height) / depth pixels
  // wide; one voxel is that / tan(fov / 2), so the voxels of a surface touch.
  var pointSize = Math.max(D.resolution_m, 1e-3) / Math.tan(camera.fov * Math.PI / 360);
  var material = new THREE.PointsMaterial({size: pointSize, vertexColors: THREE.VertexColors,
                                           sizeAttenuation: true, clippingPlanes: [cut, floorLow]});
  var points = new THREE.Points(geometry, material);
  scene.add(points);

  // The colours: palette[V], red for V = 0 when asked; with a selected station, the voxels only it
  // sees in magenta and the others faded.
  var selected = -1;
  function recolour() {
    for (var i = 0; i < n; i++) {
      var q = v[i], r, g, b;
      if (q === 0 && unseenRed) {
        r = 0.86; g = 0.1; b = 0.1;
      } else {
        r = palette[3 * q] / 255; g = palette[3 * q + 1] / 255; b = palette[3 * q + 2] / 255;
      }
      if (selected >= 0 && sole) {
        if (sole[i] === selected + 1) {
          r = 1; g = 0.1; b = 0.85;
        } else {
          r = 0.14 + 0.25 * r; g = 0.15 + 0.25 * g; b = 0.17 + 0.25 * b;
        }
      }
      colours[3 * i] = r; colours[3 * i + 1] = g; colours[3 * i + 2] = b;
    }
    swatch.style.background = unseenRed ? 'rgb(219,26,26)' : 'rgb(' + palette[0] + ',' + palette[1] + ',' + palette[2] + ')';
    colourAttribute.needsUpdate = true;
    requestRender();
  }

  // Stations: numbered markers (plan order, 1-based), always in front.
  var markerSize = Math.max(4 * D.resolution_m, extent / 40);
  function markerTexture(label, ring, fill) {
    var c = document.createElement('canvas');
    c.width = c.height = 64;
    var g = c.getContext('2d');
    g.beginPath();
    g.arc(32, 32, 27, 0, 2 * Math.PI);
    g.fillStyle = fill;
    g.fill();
    g.lineWidth = 6;
    g.strokeStyle = ring;
    g.stroke();
    g.fillStyle = '#000';
    g.font = 'bold ' + (label.length > 2 ? 20 : 28) + 'px sans-serif';
    g.textAlign = 'center';
    g.textBaseline = 'middle';
    g.fillText(label, 32, 33);
    return new THREE.CanvasTexture(c);
  }
  var markers = [];
  stations.forEach(function (s, k) {
    var normal = markerTexture(String(s.number), s.fixed ? '#000' : '#d72828', '#fff');
    var m = new THREE.Sprite(new THREE.SpriteMaterial({map: normal, depthTest: false, depthWrite: false,
                                                       sizeAttenuation: true}));
    m.position.copy(local(s.position));
    m.scale.set(markerSize, markerSize, 1);
    m.renderOrder = 10;
    m.userData = {station: k, normal: normal, selected: null};
    scene.add(m);
    markers.push(m);
  });

  // The scan graph's links at the drawing threshold (as heatmap.png), light blue.
  var edgeGroup = new THREE.Group();
  var edgePoints = [];
  D.edges.forEach(function (e) {
    if (e[0] < stations.length && e[1] < stations.length) {
      edgePoints.push(local(stations[e[0]].position), local(stations[e[1]].position));
    }
  });
  if (edgePoints.length) {
    edgeGroup.add(new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(edgePoints),
                                         new THREE.LineBasicMaterial({color: 0x7fd4ff, transparent: true, opacity: 0.85,
                                                                       clippingPlanes: floorClipping})));
  }
  scene.add(edgeGroup);

  // The walking route, orange, one voxel above the floor it follows.
  var routeGroup = new THREE.Group();
  var lift = Math.max(D.resolution_m, 0.02);
  D.route.forEach(function (flat) {
    var pts = [];
    for (var j = 0; j + 2 < flat.length; j += 3) pts.push(local([flat[j], flat[j + 1], flat[j + 2] + lift]));
    if (pts.length > 1) {
      routeGroup.add(new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts),
                                    new THREE.LineBasicMaterial({color: 0xff8c00, depthTest: false,
                                                                 clippingPlanes: floorClipping})));
    }
  });
  routeGroup.renderOrder = 5;
  scene.add(routeGroup);

  checkbox('walking route (orange)', true, function (on) { routeGroup.visible = on; requestRender(); });
  // Hundreds of links hide the scene: then they start hidden.
  edgeGroup.visible = D.edges.length <= 200;
  checkbox('overlap links (blue): ' + D.edges.length + ' pairs of stations overlapping \u2265 ' + num(D.edge_min_overlap, 2),
           edgeGroup.visible, function (on) { edgeGroup.visible = on; requestRender(); });

  // Keep-out zones: translucent red prisms with solid edges, their heights clamped to 1 m around
  // the scene (a zone may reach far above and below it).
  var zoneGroup = new THREE.Group();
  D.keep_out.forEach(function (z) {
    var shape = new THREE.Shape();
    for (var j = 0; j + 1 < z.outline.length; j += 2) {
      var x = z.outline[j] - origin[0], y = z.outline[j + 1] - origin[1];
      if (j === 0) shape.moveTo(x, y); else shape.lineTo(x, y);
    }
    var bottom = Math.max(z.min[2] - origin[2], box.min.z - 1), top = Math.min(z.max[2] - origin[2], box.max.z + 1);
    if (!(top > bottom)) return;
    var prism = new THREE.ExtrudeBufferGeometry(shape, {depth: top - bottom, bevelEnabled: false});
    var fill = new THREE.Mesh(prism, new THREE.MeshBasicMaterial({color: 0xff2828, transparent: true, opacity: 0.3,
                                                                  depthWrite: false, side: THREE.DoubleSide,
                                                                  clippingPlanes: floorClipping}));
    var edges = new THREE.LineSegments(new THREE.EdgesGeometry(prism),
                                       new THREE.LineBasicMaterial({color: 0xff2828, clippingPlanes: floorClipping}));
    fill.position.z = edges.position.z = bottom;
    zoneGroup.add(fill);
    zoneGroup.add(edges);
  });
  scene.add(zoneGroup);
  var zonesDrawn = zoneGroup.children.filter(function (o) { return o.isMesh; }).length;
  if (D.keep_out.length) {
    checkbox('keep-out zones (translucent red): ' + zonesDrawn, true, function (on) { zoneGroup.visible = on; requestRender(); });
  }

  // The scale: a grid of round squares (1, 2 or 5 x 10^k m, about a dozen across the scene) on the
  // shown floor, its lines at whole multiples of the square in the input's frame.
  var square = roundStep(Math.max(extent / 12, D.resolution_m, 0.01));
  var squares = 2 * Math.ceil(extent / square / 2) + 2;
  var gridGroup = new THREE.Group();
  var grid = new THREE.GridHelper(squares * square, squares, 0x9aa0a6, 0x9aa0a6);
  grid.rotation.x = Math.PI / 2;
  grid.material.transparent = true;
  grid.material.opacity = 0.55;
  gridGroup.add(grid);
  var centre = box.getCenter(new THREE.Vector3());
  gridGroup.position.x = Math.round((centre.x + origin[0] + frame[0]) / square) * square - origin[0] - frame[0];
  gridGroup.position.y = Math.round((centre.y + origin[1] + frame[1]) / square) * square - origin[1] - frame[1];
  scene.add(gridGroup);
  var scaleNote = document.getElementById('scale');
  checkbox('metre grid on the floor (grey): squares of ' + square + ' m', true, function (on) {
    gridGroup.visible = on;
    scaleNote.style.display = on ? '' : 'none';
    requestRender();
  });

  // Hide what lies above a height (ceilings), by default 1 m above the highest station.
  var zLow = origin[2] + box.min.z, zHigh = origin[2] + box.max.z;
  var stationTop = -Infinity;
  stations.forEach(function (s) { stationTop = Math.max(stationTop, s.position[2]); });
  var cutZ = isFinite(stationTop) ? Math.min(stationTop + 1, zHigh) : zHigh;
  var cutLabel = el('label');
  var slider = document.createElement('input');
  slider.type = 'range';
  slider.min = String(zLow);
  slider.max = String(zHigh + 1e-6);
  slider.step = String(Math.max(D.resolution_m, (zHigh - zLow) / 500, 1e-3));
  slider.value = String(cutZ);
  var cutText = el('span');
  function applyCut() {
    cutZ = Number(slider.value);
    cut.constant = Math.min(cutZ - origin[2], floorHigh.constant);
    cutText.textContent = cutZ >= zHigh ? 'voxels above z = ' + num(cutZ + frame[2], 2) + ' m hidden (none)'
                                        : 'voxels above z = ' + num(cutZ + frame[2], 2) + ' m hidden (ceilings)';
    requestRender();
  }
  slider.addEventListener('input', applyCut);
  cutLabel.appendChild(cutText);
  cutLabel.appendChild(slider);
  controlsBox.appendChild(cutLabel);

  // The floor selector: all floors, or one floor's band of voxels (from half a metre below its
  // floor's top to half a metre below the next floor's), its stations, their table rows and the
  // route, links and zones within the band; the grid lies on the shown floor (the lowest for all).
  var floorSelect = document.getElementById('floor');
  D.floors.forEach(function (f, i) {
    var option = el('option', 'floor ' + f.name + ' (top at z = ' + num(f.floor_z + frame[2], 2) + ' m)');
    option.value = String(i);
    floorSelect.appendChild(option);
  });
  var shownFloor = -1;
  function onShownFloor(k) { return shownFloor < 0 || stations[k].page_floor === shownFloor; }
  function showFloor(f) {
    shownFloor = f >= 0 && f < D.floors.length ? f : -1;
    var band = shownFloor < 0 ? null : D.floors[shownFloor];
    var low = band && band.from_z !== null ? band.from_z - origin[2] : box.min.z - 1;
    var high = band && band.to_z !== null ? band.to_z - origin[2] : box.max.z + 1;
    floorLow.constant = -low;
    floorHigh.constant = high;
    var gridFloor = D.floors.length ? D.floors[Math.max(shownFloor, 0)] : null;
    gridGroup.position.z = gridFloor ? gridFloor.floor_z - origin[2] + Math.max(0.01, 0.1 * D.resolution_m) : box.min.z;
    scaleNote.textContent = 'Grid squares of ' + square + ' m (all lengths in metres)' +
        (gridFloor ? ' on floor ' + gridFloor.name + ', z = ' + num(gridFloor.floor_z + frame[2], 2) + ' m' : '');
    var visible = 0;
    markers.forEach(function (m, k) {
      m.visible = onShownFloor(k);
      rows[k].hidden = !m.visible;
      visible += m.visible ? 1 : 0;
    });
    var onFloor = 0;
    for (var i = 0; i < n; i++) if (positions[3 * i + 2] >= low && positions[3 * i + 2] < high) onFloor++;
    R.floor = band ? band.name : 'all';
    R.visibleStationMarkers = visible;
    R.pointsOnFloor = onFloor;
    body.setAttribute('data-floor', R.floor);
    body.setAttribute('data-visible-station-markers', String(visible));
    body.setAttribute('data-points-on-floor', String(onFloor));
    floorSelect.value = shownFloor < 0 ? 'all' : String(shownFloor);
    if (selected >= 0 && !onShownFloor(selected)) select(-1);
    // The camera keeps its direction and distance and looks at the shown floor, a metre above it.
    var dz = (band ? band.floor_z - origin[2] + 1 : homeTargetZ) - controls.target.z;
    controls.target.z += dz;
    camera.position.z += dz;
    controls.update();
    applyCut();
  }
  floorSelect.addEventListener('change', function () {
    showFloor(floorSelect.value === 'all' ? -1 : Number(floorSelect.value));
  });
  R.showFloor = showFloor;

  // Selecting a station: its marker in magenta, the voxels only it sees in magenta.
  function select(k) {
    if (selected >= 0) {
      markers[selected].material.map = markers[selected].userData.normal;
      rows[selected].classList.remove('selected');
    }
    selected = k;
    if (k >= 0) {
      var m = markers[k];
      if (!m.userData.selected) m.userData.selected = markerTexture(String(stations[k].number), '#ff1ad9', '#ffd0f3');
      m.material.map = m.userData.selected;
      rows[k].classList.add('selected');
      if (!sole) {
        selectionNote.textContent = 'Station ' + stations[k].number + ' selected. The highlight of the voxels only ' +
            'it sees is unavailable: this plan carries no per-voxel sole viewer (Evaluation::sole_viewer).';
      } else {
        var drawn = 0;
        for (var i = 0; i < n; i++) if (sole[i] === k + 1) drawn++;
        selectionNote.textContent = 'Station ' + stations[k].number + ': ' + count(stations[k].sole_voxels) +
            ' voxels only it sees (magenta' + (P.drawn === P.total ? '' : ', ' + count(drawn) + ' of them drawn') +
            '). Click it again to clear.';
      }
    } else {
      selectionNote.textContent = sole ? 'Click a station (marker or row) to highlight the voxels only it sees.'
                                       : 'The highlight of the voxels only one station sees is unavailable: this ' +
                                         'plan carries no per-voxel sole viewer (Evaluation::sole_viewer).';
    }
    recolour();
  }

  // ---------- camera, controls, rendering ----------
  var target = box.getCenter(new THREE.Vector3());
  target.z = Math.min(target.z, (box.min.z + cut.constant) / 2);
  camera.position.copy(target).add(new THREE.Vector3(0.1, -0.8, 1).normalize().multiplyScalar(extent * 1.1));
  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(target);
  var homeTargetZ = target.z;
  controls.update();
  var pending = false;
  // For print, a picture of the view (#snapshot) taken half a second after the view last changed
  // and again just before printing. While printing, the hidden view keeps its size and picture.
  var snapshot = document.getElementById('snapshot');
  var snapshotTimer = null;
  var printing = false;
  function takeSnapshot() {
    snapshotTimer = null;
    if (!printing) snapshot.src = renderer.domElement.toDataURL('image/png');
  }
  function render() {
    pending = false;
    renderer.render(scene, camera);
    if (snapshotTimer !== null) clearTimeout(snapshotTimer);
    snapshotTimer = setTimeout(takeSnapshot, 500);
  }
  window.addEventListener('beforeprint', function () {
    render();
    takeSnapshot();
    printing = true;
  });
  window.addEventListener('afterprint', function () {
    printing = false;
    resize();
  });
  function requestRender() {
    if (!pending) {
      pending = true;
      requestAnimationFrame(render);
    }
  }
  controls.addEventListener('change', requestRender);
  function resize() {
    if (printing) return;
    var w = Math.max(view.clientWidth, 1), h = Math.max(view.clientHeight, 1);
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    requestRender();
  }
  window.addEventListener('resize', resize);

  // A click (not a drag) on a marker selects its station.
  var raycaster = new THREE.Raycaster();
  var down = null;
  renderer.domElement.addEventListener('pointerdown', function (e) { down = [e.clientX, e.clientY]; });
  renderer.domElement.addEventListener('pointerup', function (e) {
    if (!down || Math.abs(e.clientX - down[0]) + Math.abs(e.clientY - down[1]) > 5) return;
    var rect = renderer.domElement.getBoundingClientRect();
    var mouse = new THREE.Vector2((e.clientX - rect.left) / rect.width * 2 - 1, -(e.clientY - rect.top) / rect.height * 2 + 1);
    raycaster.setFromCamera(mouse, camera);
    var hits = raycaster.intersectObjects(markers.filter(function (m) { return m.visible; }));
    if (hits.length) {
      var k = hits[0].object.userData.station;
      select(selected === k ? -1 : k);
      rows[k].scrollIntoView({block: 'nearest'});
    }
  });

  // report.html#floor=NAME opens with that floor shown (e.g. #floor=L1).
  var wantedFloor = /floor=([^&]+)/.exec(window.location.hash);
  var floorNames = D.floors.map(function (f) { return f.name; });
  showFloor(wantedFloor ? floorNames.indexOf(decodeURIComponent(wantedFloor[1])) : -1);
  // report.html#station=N opens with station N (1-based, plan order) selected.
  var wanted = /station=(\d+)/.exec(window.location.hash);
  select(wanted && wanted[1] >= 1 && wanted[1] <= stations.length ? Number(wanted[1]) - 1 : -1);
  resize();
  render();
  // For tests: where station k's marker is on the screen (client pixels), to click it.
  R.markerScreenPosition = function (k) {
    var p = markers[k].position.clone().project(camera);
    var rect = renderer.domElement.getBoundingClientRect();
    return [rect.left + (p.x + 1) / 2 * rect.width, rect.top + (1 - p.y) / 2 * rect.height];
  };
  requestAnimationFrame(function () {
    R.ready = true;
    R.stationMarkers = scene.children.filter(function (o) { return o.isSprite; }).length;
    R.pointsDrawn = geometry.getAttribute('position').count;
    body.setAttribute('data-station-markers', String(R.stationMarkers));
    body.setAttribute('data-points-drawn', String(R.pointsDrawn));
    R.keepOutZones = zonesDrawn;
    body.setAttribute('data-keep-out-zones', String(zonesDrawn));
    body.setAttribute('data-errors', String(R.errors.length));
    body.setAttribute('data-ready', 'true');
    document.title = document.title + ' \u2014 ready';
  });
})();
