// tumble's offline trajectory viewer: draws the scene that tumble.viz.viewer wrote into #tumble-scene with the
// embedded plotly.js, frame by frame. Every number comes from Python (rotation matrices, positions, arrows);
// this file only applies them (world = R v + p) and runs the controls. window.tumbleViewer exposes the state
// the tests read back: the frame shown and, per solid, the rotation and position applied.
(function () {
  "use strict";
  const S = JSON.parse(document.getElementById("tumble-scene").textContent);
  const F = S.t.length;
  const main = document.getElementById("tumble-3d");
  const panel = document.getElementById("tumble-panel");
  const polhode = document.getElementById("tumble-polhode");
  const slider = document.getElementById("tumble-slider");
  const clock = document.getElementById("tumble-clock");
  const playButton = document.getElementById("tumble-play");
  const speedSelect = document.getElementById("tumble-speed");
  const config = {displaylogo: false, responsive: true};
  const sideConfig = {displaylogo: false, responsive: true, displayModeBar: false};
  const state = {frame: 0, playing: false, applied: {}, ready: false, simTime: S.t[0], last: null};

  function at(array, f) { return array[Math.min(f, array.length - 1)]; }

  // world coordinates of a solid at frame f: w = R v + p, as three arrays for plotly
  function placeSolid(solid, f) {
    const R = at(solid.rotation, f), p = at(solid.position, f), v = solid.vertices;
    const x = new Array(v.length), y = new Array(v.length), z = new Array(v.length);
    for (let k = 0; k < v.length; k++) {
      const a = v[k][0], b = v[k][1], c = v[k][2];
      x[k] = R[0][0] * a + R[0][1] * b + R[0][2] * c + p[0];
      y[k] = R[1][0] * a + R[1][1] * b + R[1][2] * c + p[1];
      z[k] = R[2][0] * a + R[2][1] * b + R[2][2] * c + p[2];
    }
    state.applied[solid.name] = {rotation: R, position: p};
    return [x, y, z];
  }

  function column(points, k) { return points.map(function (point) { return point === null ? null : point[k]; }); }

  function linePoints(line, f) {
    const points = line.trail ? line.points.slice(0, f + 1) : at(line.points, f);
    return [column(points, 0), column(points, 1), column(points, 2)];
  }

  function mainTraces() {
    const traces = [];
    S.solids.forEach(function (solid) {
      const xyz = placeSolid(solid, 0);
      const faces = solid.faces;
      traces.push({type: "mesh3d", name: solid.name, x: xyz[0], y: xyz[1], z: xyz[2],
                   i: faces.map(function (t) { return t[0]; }), j: faces.map(function (t) { return t[1]; }),
                   k: faces.map(function (t) { return t[2]; }), color: solid.color, opacity: solid.opacity,
                   flatshading: true, showlegend: solid.legend, hoverinfo: "name",
                   lighting: {ambient: 0.55, diffuse: 0.8, specular: 0.1}});
    });
    S.lines.forEach(function (line) {
      const xyz = linePoints(line, 0);
      traces.push({type: "scatter3d", mode: line.markers ? "lines+markers" : "lines", name: line.name,
                   x: xyz[0], y: xyz[1], z: xyz[2], line: {color: line.color, width: line.width},
                   marker: {size: line.markers ? 5 : 3, color: line.color}, showlegend: line.legend, hoverinfo: "name",
                   connectgaps: false});
    });
    return traces;
  }

  // the traces that change from frame to frame, and their indices in the main plot
  const moving = [];
  S.solids.forEach(function (solid, k) { if (solid.rotation.length > 1 || solid.position.length > 1) moving.push(k); });
  S.lines.forEach(function (line, k) {
    if (line.trail || line.points.length > 1) moving.push(S.solids.length + k);
  });

  function drawMain(f) {
    const x = [], y = [], z = [];
    moving.forEach(function (k) {
      const xyz = k < S.solids.length ? placeSolid(S.solids[k], f) : linePoints(S.lines[k - S.solids.length], f);
      x.push(xyz[0]); y.push(xyz[1]); z.push(xyz[2]);
    });
    return moving.length ? Plotly.restyle(main, {x: x, y: y, z: z}, moving) : Promise.resolve();
  }

  function panelLayout() {
    return {title: {text: S.panel.title, font: {size: 13}}, margin: {l: 55, r: 10, t: 30, b: 40},
            xaxis: {title: {text: "time t (s)"}}, yaxis: {title: {text: S.panel.unit}},
            legend: {orientation: "h", y: -0.3}, showlegend: true,
            shapes: [{type: "line", xref: "x", yref: "paper", x0: S.t[0], x1: S.t[0], y0: 0, y1: 1,
                      line: {color: "#444", width: 1.5, dash: "dot"}}]};
  }

  function polhodeTraces() {
    const P = S.polhode, e = P.ellipsoid;
    return [
      {type: "mesh3d", name: "energy ellipsoid ω·Iω = 2T", x: column(e.vertices, 0), y: column(e.vertices, 1),
       z: column(e.vertices, 2), i: e.faces.map(function (t) { return t[0]; }),
       j: e.faces.map(function (t) { return t[1]; }), k: e.faces.map(function (t) { return t[2]; }),
       color: "#9ecae1", opacity: 0.35, hoverinfo: "name"},
      {type: "scatter3d", mode: "lines", name: "polhode ω(t)", x: column(P.points, 0), y: column(P.points, 1),
       z: column(P.points, 2), line: {color: "#d62728", width: 4}},
      {type: "scatter3d", mode: "markers", name: "ω now", x: [P.points[0][0]], y: [P.points[0][1]],
       z: [P.points[0][2]], marker: {size: 5, color: "#000"}}];
  }

  function sceneLayout(range, titles) {
    const axis = function (name) {
      return {title: {text: name}, range: [-range, range], autorange: false, zeroline: false};
    };
    return {xaxis: axis(titles[0]), yaxis: axis(titles[1]), zaxis: axis(titles[2]), aspectmode: "cube",
            camera: {eye: {x: 1.5, y: 1.3, z: 0.9}}};
  }

  function show(f) {
    f = Math.max(0, Math.min(F - 1, Math.round(f)));
    state.frame = f;
    slider.value = f;
    clock.textContent = "t = " + S.t[f].toPrecision(6) + " s   frame " + (f + 1) + " of " + F + "   sample " +
      (S.sample[f] + 1) + " of " + S.samples;
    const work = [drawMain(f)];
    if (S.panel) work.push(Plotly.relayout(panel, {"shapes[0].x0": S.t[f], "shapes[0].x1": S.t[f]}));
    if (S.polhode) {
      const w = S.polhode.points[f];
      work.push(Plotly.restyle(polhode, {x: [[w[0]]], y: [[w[1]]], z: [[w[2]]]}, [2]));
    }
    return Promise.all(work);
  }

  // Simulated time advances with the wall clock times the speed; a pause of the page (a busy machine, a hidden
  // tab) counts as at most MAX_STEP s, so playback never jumps ahead.
  const MAX_STEP = 0.1;

  function tick() {
    if (!state.playing) return;
    const now = performance.now();
    if (state.last !== null) {
      state.simTime += Math.min(MAX_STEP, (now - state.last) / 1000) * Number(speedSelect.value);
    }
    state.last = now;
    let f = state.frame;
    while (f < F - 1 && S.t[f + 1] <= state.simTime) f++;
    const done = f >= F - 1;
    show(f).then(function () {
      if (done) pause(); else requestAnimationFrame(tick);
    });
  }

  function play() {
    if (state.frame >= F - 1) show(0);
    state.simTime = S.t[state.frame];
    state.last = null;
    state.playing = true;
    playButton.textContent = "Pause";
    requestAnimationFrame(tick);
  }

  function pause() {
    state.playing = false;
    playButton.textContent = "Play";
  }

  S.speeds.forEach(function (s) {
    const option = document.createElement("option");
    option.value = s;
    option.textContent = s + "×";
    speedSelect.appendChild(option);
  });
  speedSelect.value = String(S.speed);
  slider.max = F - 1;
  slider.addEventListener("input", function () { pause(); show(Number(slider.value)); });
  playButton.addEventListener("click", function () { if (state.playing) pause(); else play(); });
  document.getElementById("tumble-notes").innerHTML = S.notes.map(function (n) {
    const li = document.createElement("li");
    li.textContent = n;
    return li.outerHTML;
  }).join("");
  document.getElementById("tumble-title").textContent = S.title;

  const plots = [Plotly.newPlot(main, mainTraces(), {
    scene: sceneLayout(S.range, ["x", "y", "z"].map(function (a) { return a + " " + S.frame + " (m)"; })),
    margin: {l: 0, r: 0, t: 0, b: 0}, legend: {x: 0, y: 1}, uirevision: "keep"}, config)];
  if (S.panel) {
    plots.push(Plotly.newPlot(panel, S.panel.series.map(function (s) {
      return {type: "scatter", mode: "lines", name: s.name, x: S.t, y: s.values, line: {color: s.color, width: 1.5}};
    }), panelLayout(), sideConfig));
  } else {
    panel.style.display = "none";
  }
  if (S.polhode) {
    plots.push(Plotly.newPlot(polhode, polhodeTraces(), {
      scene: sceneLayout(S.polhode.range, ["ω₁ (rad/s)", "ω₂ (rad/s)", "ω₃ (rad/s)"]),
      title: {text: "polhode on the energy ellipsoid (principal axes)", font: {size: 13}},
      margin: {l: 0, r: 0, t: 30, b: 0}, showlegend: false, uirevision: "keep"}, sideConfig));
  } else {
    polhode.style.display = "none";
  }
  window.tumbleViewer = {state: state, show: show, play: play, pause: pause, frames: F, main: main,
                         panel: panel, polhode: polhode, solids: S.solids.map(function (s) { return s.name; }),
                         lines: S.lines.map(function (l) { return l.name; })};
  Promise.all(plots).then(function () { return show(0); }).then(function () { state.ready = true; });
})();
