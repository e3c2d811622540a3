// armcal 3D cell view (Canvas 2D). Reads the scene JSON of its own cell-view section (world
// geometry in mm, computed by armcal), projects it orthographically with an orbit
// camera and draws it back to front (painter's algorithm). After every draw it records the
// number of non-background pixels in canvas.dataset.inkPixels and sets data-drawn="1".
(function (section) {
  'use strict';
  if (!section) { return; }
  var scene = JSON.parse(section.querySelector('script.cell-view-data').textContent);
  var canvas = section.querySelector('canvas');
  var ctx = canvas.getContext('2d');
  var select = section.querySelector('select.cell-view-design');
  var slider = section.querySelector('input.cell-view-slider');
  var prevButton = section.querySelector('button.cell-view-prev');
  var nextButton = section.querySelector('button.cell-view-next');
  var label = section.querySelector('.cell-view-label');
  var poseText = section.querySelector('.cell-view-pose');

  var BG = [250, 250, 250];
  var ROBOT = [236, 128, 28];
  var TOOL = [120, 120, 130];
  var OBSTACLE = [118, 138, 168];
  var HIT = [214, 32, 32];
  var OK_BEAM = [20, 150, 60];

  var b0 = scene.bounds[0], b1 = scene.bounds[1];
  var f0 = scene.focus[0], f1 = scene.focus[1];
  var center = [(f0[0] + f1[0]) / 2, (f0[1] + f1[1]) / 2, (f0[2] + f1[2]) / 2];
  var halfDiagonal = 0.5 * Math.sqrt(sq(b1[0] - b0[0]) + sq(b1[1] - b0[1]) + sq(b1[2] - b0[2]));
  var view = { design: 0, pose: 0, yaw: -1.0, pitch: 0.5, zoom: 1.0 };
  var cam = null;
  // Pixels per mm at zoom 1: the focus box (robot at every pose, targets, tracker) fills the
  // canvas in the initial view.
  var fitScale = (function () {
    view.zoom = 1; cam = camera(1);
    var w = 0, h = 0;
    [f0[0], f1[0]].forEach(function (x) { [f0[1], f1[1]].forEach(function (y) { [f0[2], f1[2]].forEach(function (z) {
      var p = project([x, y, z]);
      w = Math.max(w, Math.abs(p[0] - cam.cx)); h = Math.max(h, Math.abs(p[1] - cam.cy));
    }); }); });
    return 0.92 * Math.min(canvas.width / (2 * w), canvas.height / (2 * h));
  })();

  function sq(x) { return x * x; }
  function clamp(x, lo, hi) { return Math.max(lo, Math.min(hi, x)); }
  function rgb(c, alpha) {
    var s = Math.round(c[0]) + ',' + Math.round(c[1]) + ',' + Math.round(c[2]);
    return alpha === undefined ? 'rgb(' + s + ')' : 'rgba(' + s + ',' + alpha + ')';
  }
  function mix(c, d, t) {
    return [c[0] + (d[0] - c[0]) * t, c[1] + (d[1] - c[1]) * t, c[2] + (d[2] - c[2]) * t];
  }

  // Camera: eye direction e (from the scene towards the viewer), screen right u, screen up v.
  function camera(pxPerMm) {
    var cy = Math.cos(view.yaw), sy = Math.sin(view.yaw);
    var cp = Math.cos(view.pitch), sp = Math.sin(view.pitch);
    var scale = view.zoom * pxPerMm;
    return {
      e: [cp * cy, cp * sy, sp],
      u: [-sy, cy, 0],
      v: [-sp * cy, -sp * sy, cp],
      scale: scale,
      cx: canvas.width / 2,
      cy: canvas.height / 2
    };
  }
  // Screen x, y (px) and depth (mm, larger is nearer the viewer).
  function project(p) {
    var d0 = p[0] - center[0], d1 = p[1] - center[1], d2 = p[2] - center[2];
    return [
      cam.cx + cam.scale * (d0 * cam.u[0] + d1 * cam.u[1]),
      cam.cy - cam.scale * (d0 * cam.v[0] + d1 * cam.v[1] + d2 * cam.v[2]),
      d0 * cam.e[0] + d1 * cam.e[1] + d2 * cam.e[2]
    ];
  }
  // 0 at the far side of the scene, 1 at the near side.
  function nearness(depth) { return clamp(0.5 + depth / (2 * halfDiagonal), 0, 1); }

  function capsuleItem(a, b, r, color, name) {
    var pa = project(a), pb = project(b);
    var depth = (pa[2] + pb[2]) / 2;
    return {
      depth: depth,
      draw: function () {
        var w = Math.max(2, 2 * r * cam.scale);
        var shade = mix(color, BG, 0.45 * (1 - nearness(depth)));
        ctx.lineCap = 'round';
        ctx.beginPath(); ctx.moveTo(pa[0], pa[1]); ctx.lineTo(pb[0], pb[1]);
        ctx.strokeStyle = rgb(mix(shade, [0, 0, 0], 0.35)); ctx.lineWidth = w + 2; ctx.stroke();
        ctx.strokeStyle = rgb(shade); ctx.lineWidth = w; ctx.stroke();
        // Highlight towards the upper left: a lighter, narrower stroke.
        var off = 0.18 * w;
        ctx.beginPath(); ctx.moveTo(pa[0] - off, pa[1] - off); ctx.lineTo(pb[0] - off, pb[1] - off);
        ctx.strokeStyle = rgb(mix(shade, [255, 255, 255], 0.35)); ctx.lineWidth = 0.35 * w;
        ctx.stroke();
      },
      // Obstacle names near the second end, clear of a robot standing at the middle.
      label: name ? { at: [pa[0] + 0.8 * (pb[0] - pa[0]), pa[1] + 0.8 * (pb[1] - pa[1])], text: name } : null
    };
  }
  function polygonPath(points) {
    ctx.beginPath();
    points.forEach(function (p, k) { if (k === 0) { ctx.moveTo(p[0], p[1]); } else { ctx.lineTo(p[0], p[1]); } });
    ctx.closePath();
  }
  // A translucent plane polygon; its label goes near its top-most corner, inside it.
  function planeItem(plane, hit, labels) {
    var pts = plane.corners.map(project);
    var color = hit ? HIT : OBSTACLE;
    var cx = 0, cy = 0, top = pts[0];
    pts.forEach(function (p) { cx += p[0]; cy += p[1]; if (p[1] < top[1]) { top = p; } });
    cx /= pts.length; cy /= pts.length;
    labels.push({ at: [top[0] + 0.15 * (cx - top[0]), top[1] + 0.15 * (cy - top[1])], text: plane.name,
      color: rgb(mix(color, [0, 0, 0], 0.3)) });
    return function () {
      polygonPath(pts);
      ctx.fillStyle = rgb(color, 0.13); ctx.fill();
      ctx.strokeStyle = rgb(color, 0.55); ctx.lineWidth = 1; ctx.stroke();
    };
  }
  // The faces of a box obstacle that face the camera, each sorted by its mean depth; the
  // name on the top face's centre.
  function boxItems(faces, color) {
    var out = [];
    faces.forEach(function (f, k) {
      if (f.normal[0] * cam.e[0] + f.normal[1] * cam.e[1] + f.normal[2] * cam.e[2] <= 0) { return; }
      var pts = f.corners.map(project);
      var depth = 0, cx = 0, cy = 0;
      pts.forEach(function (p) { depth += p[2]; cx += p[0]; cy += p[1]; });
      out.push({ depth: depth / 4, draw: function () {
        polygonPath(pts);
        ctx.fillStyle = rgb(color, 0.45); ctx.fill();
        ctx.strokeStyle = rgb(mix(color, [0, 0, 0], 0.3)); ctx.lineWidth = 1; ctx.stroke();
      }, label: k === 4 ? { at: [cx / 4, cy / 4], text: f.name } : null });
    });
    return out;
  }
  function gridItem() {
    var z = scene.ground, step = 500;
    return function () {
      ctx.strokeStyle = 'rgba(0,0,0,0.10)'; ctx.lineWidth = 1;
      var x, y;
      for (x = Math.ceil(b0[0] / step) * step; x <= b1[0]; x += step) {
        line(project([x, b0[1], z]), project([x, b1[1], z]));
      }
      for (y = Math.ceil(b0[1] / step) * step; y <= b1[1]; y += step) {
        line(project([b0[0], y, z]), project([b1[0], y, z]));
      }
    };
  }
  function line(p, q) { ctx.beginPath(); ctx.moveTo(p[0], p[1]); ctx.lineTo(q[0], q[1]); ctx.stroke(); }
  function text(s, x, y, color) {
    ctx.font = '13px sans-serif';
    ctx.textAlign = 'center'; ctx.textBaseline = 'middle';
    ctx.lineWidth = 3; ctx.strokeStyle = 'rgba(250,250,250,0.85)'; ctx.strokeText(s, x, y);
    ctx.fillStyle = color || '#222'; ctx.fillText(s, x, y);
  }
  function dot(p, radiusPx, color) {
    ctx.beginPath(); ctx.arc(p[0], p[1], radiusPx, 0, 2 * Math.PI);
    ctx.fillStyle = rgb(color); ctx.fill();
    ctx.strokeStyle = rgb(mix(color, [0, 0, 0], 0.4)); ctx.lineWidth = 1; ctx.stroke();
  }
  // Axis triad in the lower left corner: the world axes as seen by the camera.
  function triad() {
    var o = [48, canvas.height - 48], len = 34;
    var axes = [[[1, 0, 0], 'x', [200, 40, 40]], [[0, 1, 0], 'y', [40, 150, 40]], [[0, 0, 1], 'z', [40, 70, 210]]];
    axes.sort(function (p, q) {
      return (p[0][0] * cam.e[0] + p[0][1] * cam.e[1] + p[0][2] * cam.e[2]) -
        (q[0][0] * cam.e[0] + q[0][1] * cam.e[1] + q[0][2] * cam.e[2]);
    });
    axes.forEach(function (ax) {
      var d = ax[0];
      var sx = d[0] * cam.u[0] + d[1] * cam.u[1];
      var sy = d[0] * cam.v[0] + d[1] * cam.v[1] + d[2] * cam.v[2];
      var tip = [o[0] + len * sx, o[1] - len * sy];
      ctx.strokeStyle = rgb(ax[2]); ctx.lineWidth = 3; ctx.lineCap = 'round';
      line(o, tip);
      text(ax[1], o[0] + (len + 11) * sx, o[1] - (len + 11) * sy, rgb(ax[2]));
    });
  }

  function draw() {
    cam = camera(fitScale);
    var design = scene.designs[view.design];
    var pose = design.poses[view.pose];
    var hitObstacle = {};
    pose.hit_obstacles.forEach(function (n) { hitObstacle[n] = true; });
    var hitCapsule = {};
    pose.hit.forEach(function (i) { hitCapsule[i] = true; });

    ctx.setLineDash([]);
    ctx.fillStyle = rgb(BG);
    ctx.fillRect(0, 0, canvas.width, canvas.height);

    // Half-space boundaries seen from their free side lie behind everything; seen from
    // behind, in front of everything (translucent).
    var back = [], front = [], planeLabels = [];
    scene.planes.forEach(function (pl) {
      var facing = pl.normal[0] * cam.e[0] + pl.normal[1] * cam.e[1] + pl.normal[2] * cam.e[2];
      (facing >= 0 ? back : front).push(planeItem(pl, hitObstacle[pl.name], planeLabels));
    });
    var grid = gridItem();
    if (cam.e[2] >= 0) { grid(); }
    back.forEach(function (f) { f(); });
    if (cam.e[2] < 0) { grid(); }

    var items = [];
    scene.obstacles.forEach(function (o) {
      items.push(capsuleItem(o.a, o.b, o.r, hitObstacle[o.name] ? HIT : OBSTACLE, o.name));
    });
    scene.boxes.forEach(function (faces) {
      items.push.apply(items, boxItems(faces, hitObstacle[faces[0].name] ? HIT : OBSTACLE));
    });
    scene.robot.forEach(function (c, i) {
      var e = pose.caps[i];
      var color = hitCapsule[i] ? HIT : (c.frame === 'tool' ? TOOL : ROBOT);
      items.push(capsuleItem([e[0], e[1], e[2]], [e[3], e[4], e[5]], c.r, color, null));
    });
    var beamColor = pose.ok ? OK_BEAM : HIT;
    if (scene.tracker) {
      // The beam, cut into short pieces so that it sorts correctly against the capsules.
      pose.targets.forEach(function (t) {
        var n = 24;
        for (var k = 0; k < n; k++) {
          var s0 = k / n, s1 = (k + 1) / n;
          var a = [0, 1, 2].map(function (j) { return scene.tracker[j] + (t[j] - scene.tracker[j]) * s0; });
          var b = [0, 1, 2].map(function (j) { return scene.tracker[j] + (t[j] - scene.tracker[j]) * s1; });
          items.push(beamPiece(project(a), project(b), beamColor));
        }
      });
      var pt = project(scene.tracker);
      items.push({ depth: pt[2], draw: function () {
        // A dashed plumb line to the ground helps to read the tracker's height.
        var foot = project([scene.tracker[0], scene.tracker[1], scene.ground]);
        ctx.setLineDash([4, 4]); ctx.strokeStyle = 'rgba(60,60,60,0.6)'; ctx.lineWidth = 1;
        line(pt, foot); ctx.setLineDash([]);
        dot(pt, Math.max(6, 110 * cam.scale), [70, 70, 80]);
      }, label: { at: [pt[0], pt[1] - Math.max(14, 110 * cam.scale + 10)], text: 'tracker' } });
    }
    pose.targets.forEach(function (t) {
      var p = project(t);
      items.push({ depth: p[2] + 1, draw: function () { dot(p, 4, beamColor); }, label: null });
    });
    items.sort(function (p, q) { return p.depth - q.depth; });
    items.forEach(function (it) { it.draw(); });
    front.forEach(function (f) { f(); });
    items.forEach(function (it) { if (it.label) { text(it.label.text, it.label.at[0], it.label.at[1]); } });
    planeLabels.forEach(function (l) { text(l.text, l.at[0], l.at[1], l.color); });

    triad();
    ctx.textAlign = 'left'; ctx.textBaseline = 'top'; ctx.font = '14px sans-serif';
    ctx.fillStyle = '#222';
    ctx.fillText(design.name + ': pose ' + (view.pose + 1) + ' / ' + design.poses.length +
      (pose.ok ? '' : '  (violates ' + pose.violations.length + ')'), 10, 10);
    describe(design, pose);
    countInk();
  }
  function beamPiece(pa, pb, color) {
    return { depth: (pa[2] + pb[2]) / 2, draw: function () {
      ctx.lineCap = 'round'; ctx.strokeStyle = rgb(color); ctx.lineWidth = 2; line(pa, pb);
    }, label: null };
  }

  function describe(design, pose) {
    var short = pose.below_required.length;
    var status = !pose.ok ? 'VIOLATES ' + pose.violations.join('; ') :
      short ? 'feasible, but closer than the cell\'s [design] asks: ' + pose.below_required.join('; ') : 'feasible';
    if (label) {
      label.textContent = 'pose ' + (view.pose + 1) + ' / ' + design.poses.length + ' \u2014 ' +
        (!pose.ok ? 'violates ' + pose.violations.length + ' constraint(s)' :
          short ? 'feasible, ' + short + ' margin(s) below [design]' : 'feasible');
    }
    if (poseText) {
      var q = pose.q.map(function (v, j) { return scene.joints[j].name + ' = ' + v.toFixed(2) + ' ' + scene.joints[j].unit; });
      var lines = [q.join(', ')];
      if (pose.clearance) { lines.push('smallest clearance ' + pose.clearance[0].toFixed(1) + ' mm (' + pose.clearance[1] + ')'); }
      if (pose.incidence !== null) { lines.push('incidence angle at the reflector ' + pose.incidence.toFixed(1) + '\u00b0'); }
      lines.push(status);
      poseText.textContent = lines.join('\n');
    }
  }

  function countInk() {
    var img = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    var ink = 0;
    for (var i = 0; i < img.length; i += 4) {
      if (Math.abs(img[i] - BG[0]) + Math.abs(img[i + 1] - BG[1]) + Math.abs(img[i + 2] - BG[2]) > 12) { ink++; }
    }
    canvas.dataset.inkPixels = String(ink);
    canvas.setAttribute('data-drawn', '1');
  }

  function setPose(k) {
    var n = scene.designs[view.design].poses.length;
    view.pose = clamp(k, 0, n - 1);
    if (slider) { slider.max = String(n - 1); slider.value = String(view.pose); }
    draw();
  }
  if (select) {
    select.addEventListener('change', function () { view.design = Number(select.value) || 0; setPose(view.pose); });
  }
  if (slider) { slider.addEventListener('input', function () { setPose(Number(slider.value)); }); }
  if (prevButton) { prevButton.addEventListener('click', function () { setPose(view.pose - 1); }); }
  if (nextButton) { nextButton.addEventListener('click', function () { setPose(view.pose + 1); }); }
  canvas.addEventListener('keydown', function (ev) {
    if (ev.key === 'ArrowRight') { setPose(view.pose + 1); ev.preventDefault(); }
    if (ev.key === 'ArrowLeft') { setPose(view.pose - 1); ev.preventDefault(); }
  });
  var drag = null;
  canvas.addEventListener('pointerdown', function (ev) {
    drag = [ev.clientX, ev.clientY];
    try { canvas.setPointerCapture(ev.pointerId); } catch (e) { /* not a live pointer */ }
  });
  canvas.addEventListener('pointermove', function (ev) {
    if (!drag) { return; }
    view.yaw -= (ev.clientX - drag[0]) * 0.008;
    view.pitch = clamp(view.pitch + (ev.clientY - drag[1]) * 0.008, -1.5, 1.5);
    drag = [ev.clientX, ev.clientY];
    draw();
  });
  canvas.addEventListener('pointerup', function () { drag = null; });
  canvas.addEventListener('pointercancel', function () { drag = null; });
  canvas.addEventListener('wheel', function (ev) {
    view.zoom = clamp(view.zoom * Math.exp(-ev.deltaY * 0.001), 0.2, 20);
    ev.preventDefault();
    draw();
  }, { passive: false });
  setPose(0);
})(document.currentScript && document.currentScript.closest('section.cell-view'));
