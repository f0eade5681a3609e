// The page of `whitted serve`: shows the frames the server pushes
// (server-sent events), moves the camera with the mouse, switches views
// and shows a clicked pixel's ray tree. No library, no build step.
"use strict";

const $ = (id) => document.getElementById(id);
const page = (window.whitted = {
  state: null, // the server's state: camera, flags, AOVs, structures
  frame: null, // the newest frame's description (without its picture)
  frames: 0, // frames shown
  lastTree: null, // the last ray tree shown (explain --json's)
  // ms from navigation start: this script running, the event stream
  // open, the first frame shown, the first full frame shown
  timings: { script: performance.now() },
  error: null, // the error shown, if any
});

// --- frames and errors ----------------------------------------------------

function showState(state) {
  page.state = state;
  $("scene").textContent = state.scene || "(the built-in scene)";
  $("flags").textContent = state.flags || "";
  fillSelect($("aov"), state.aovs, state.aov || "color");
  fillSelect($("accel"), state.accels, state.accel || "scene");
}

function fillSelect(select, names, chosen) {
  for (const name of names) {
    if (![...select.options].some((o) => o.value === name)) {
      select.add(new Option(name, name));
    }
  }
  if (document.activeElement !== select) select.value = chosen;
}

const events = new EventSource("/events");
events.addEventListener("open", () => {
  if (page.timings.events === undefined) page.timings.events = performance.now();
});
events.addEventListener("frame", (e) => {
  const frame = JSON.parse(e.data);
  const picture = $("picture");
  picture.onload = () => {
    page.frames += 1;
    const now = performance.now();
    if (page.timings.firstFrame === undefined) page.timings.firstFrame = now;
    if (frame.pass === "full" && page.timings.firstFull === undefined) page.timings.firstFull = now;
    picture.dataset.pass = frame.pass;
    picture.dataset.request = frame.request;
  };
  picture.src = frame.png;
  picture.style.width = frame.full_width + "px";
  delete frame.png;
  if (page.explained && page.explained.request !== frame.request) hideRays();
  page.frame = frame;
  page.error = null;
  $("error").hidden = true;
  showState(frame.state);
  $("status").textContent = `${frame.pass} pass, ${frame.width}×${frame.height}` +
    (frame.aov ? `, ${frame.aov}` : "");
  $("stats").textContent = `${frame.accel}: built in ${(frame.build_seconds * 1000).toFixed(1)} ms; ` +
    `${frame.rays} rays in ${(frame.render_seconds * 1000).toFixed(0)} ms, ` +
    `${(frame.rays_per_second / 1e6).toFixed(2)} M rays/s`;
});
events.addEventListener("warnings", (e) => {
  const warnings = JSON.parse(e.data);
  $("warnings").textContent = warnings.messages.join("\n");
  $("warnings").hidden = warnings.messages.length === 0;
});
events.addEventListener("error", (e) => {
  if (!e.data) return; // the connection dropped; EventSource reconnects
  const error = JSON.parse(e.data);
  page.error = error.message;
  $("error").textContent = error.message;
  $("error").hidden = false;
  $("status").textContent = "the scene could not be rendered: the last picture is kept";
  if (error.state) showState(error.state);
});

// --- asking for views -----------------------------------------------------

let sending = false;
let pending = null;

function ask(form) {
  pending = Object.assign(pending || {}, form);
  if (!sending) sendPending();
}

function sendPending() {
  const form = pending;
  pending = null;
  sending = true;
  fetch("/api/view", { method: "POST", body: new URLSearchParams(form) })
    .then((r) => (r.ok ? r.json().then(showState) : r.text().then(showError)))
    .catch((e) => showError(String(e)))
    .finally(() => {
      sending = false;
      if (pending) sendPending();
    });
}

function showError(text) {
  $("error").textContent = text;
  $("error").hidden = false;
}

$("aov").onchange = (e) => ask({ aov: e.target.value });
$("accel").onchange = (e) => ask({ accel: e.target.value });
$("reset").onclick = () => ask({ camera: "scene" });
$("copy").onclick = () => navigator.clipboard && navigator.clipboard.writeText($("flags").textContent);

// --- the camera under the mouse -------------------------------------------

const sub = (a, b) => a.map((v, i) => v - b[i]);
const add = (a, b) => a.map((v, i) => v + b[i]);
const scale = (a, s) => a.map((v) => v * s);
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => scale(a, 1 / Math.hypot(...a));

// Rotates v around the unit axis k by angle a (Rodrigues).
function rotate(v, k, a) {
  const c = Math.cos(a), s = Math.sin(a);
  return add(add(scale(v, c), scale(cross(k, v), s)), scale(k, dot(k, v) * (1 - c)));
}

function orbit(camera, dx, dy) {
  const up = unit(camera.up);
  let offset = sub(camera.eye, camera.look_at);
  offset = rotate(offset, up, -dx * 0.01);
  const right = unit(cross(up, offset));
  const turned = rotate(offset, right, -dy * 0.01);
  // Do not pass over the pole: the view would turn upside down.
  if (Math.abs(dot(unit(turned), up)) < 0.995) offset = turned;
  return { ...camera, eye: add(camera.look_at, offset) };
}

function pan(camera, dx, dy) {
  const forward = sub(camera.look_at, camera.eye);
  const distance = Math.hypot(...forward);
  const right = unit(cross(forward, camera.up));
  const up = unit(cross(right, forward));
  const perPixel = (2 * distance * Math.tan((camera.fov * Math.PI) / 360)) / $("picture").clientHeight;
  const move = add(scale(right, -dx * perPixel), scale(up, dy * perPixel));
  return { ...camera, eye: add(camera.eye, move), look_at: add(camera.look_at, move) };
}

function zoom(camera, factor) {
  const offset = sub(camera.eye, camera.look_at);
  return { ...camera, eye: add(camera.look_at, scale(offset, factor)) };
}

function cameraForm(camera, preview) {
  const v = (a) => a.map((x) => +x.toPrecision(9)).join(",");
  return { eye: v(camera.eye), look_at: v(camera.look_at), up: v(camera.up), fov: camera.fov, preview: preview ? 1 : 0 };
}

let drag = null;
const stage = $("stage");
stage.addEventListener("contextmenu", (e) => e.preventDefault());
stage.addEventListener("mousedown", (e) => {
  if (!page.state || !page.state.camera) return;
  drag = { x: e.clientX, y: e.clientY, camera: page.state.camera, pan: e.shiftKey || e.button === 2, moved: false };
  e.preventDefault();
});
window.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  if (!drag.moved && Math.hypot(dx, dy) < 3) return;
  drag.moved = true;
  drag.now = drag.pan ? pan(drag.camera, dx, dy) : orbit(drag.camera, dx, dy);
  ask(cameraForm(drag.now, true));
});
window.addEventListener("mouseup", (e) => {
  if (!drag) return;
  const done = drag;
  drag = null;
  if (done.moved) ask(cameraForm(done.now, false));
  else if (e.button === 0) explainAt(e);
});
let wheelTimer = null;
stage.addEventListener("wheel", (e) => {
  if (!page.state || !page.state.camera) return;
  e.preventDefault();
  const camera = zoom(page.state.camera, Math.exp(e.deltaY * 0.001));
  page.state.camera = camera;
  ask(cameraForm(camera, true));
  clearTimeout(wheelTimer);
  wheelTimer = setTimeout(() => ask(cameraForm(camera, false)), 200);
}, { passive: false });

// --- the ray tree of a pixel ----------------------------------------------

function explainAt(e) {
  const picture = $("picture");
  const frame = page.frame;
  if (!frame) return;
  const box = picture.getBoundingClientRect();
  const s = frame.full_width / box.width;
  const x = Math.floor((e.clientX - box.left) * s), y = Math.floor((e.clientY - box.top) * s);
  if (x < 0 || y < 0 || x >= frame.full_width || y >= frame.full_height) return;
  explain(x, y);
}

function explain(x, y, sample = 0) {
  const request = page.frame.request;
  const query = `x=${x}&y=${y}&sample=${sample}`;
  fetch(`/api/explain?${query}`)
    .then((r) => (r.ok ? r.json() : r.text().then((t) => Promise.reject(t))))
    .then((tree) => {
      page.lastTree = tree;
      page.explained = { x, y, sample, request };
      const root = document.createElement("ul");
      root.appendChild(treeNode(tree.tree));
      const title = document.createElement("p");
      title.textContent = `pixel ${x},${y}: ${rgbText(tree.pixel.value)}; `;
      title.append(sampleChooser(x, y, tree.sample, tree.anti_aliasing.method));
      const shown = [title];
      if (tree.left_out > 0) {
        const cut = document.createElement("p");
        cut.className = "stop";
        cut.textContent = `The tree is cut: it holds the first ${tree.limits.max_tree_rays} ` +
          `rays and light verdicts traced; ${tree.left_out} more are in the colours but not shown.`;
        shown.push(cut);
      }
      $("tree").replaceChildren(...shown, root);
      const rays = $("rays");
      rays.onload = () => { rays.hidden = false; };
      rays.src = `/api/explain.svg?${query}&request=${request}`;
      rays.style.width = page.frame.full_width + "px";
    })
    .catch((t) => showError(String(t)));
}

// The sample shown, and a choice of the pixel's others when it has some
// (its samples, or the corners its adaptive subdivision traced).
function sampleChooser(x, y, sample, method) {
  const what = method === "adaptive" ? "corner" : "sample";
  const span = document.createElement("span");
  if (sample.count < 2) {
    span.textContent = `its only ${what}`;
    return span;
  }
  const select = document.createElement("select");
  select.id = "sample";
  for (let k = 0; k < sample.count; k++) select.add(new Option(`${what} ${k}`, k));
  select.value = sample.index;
  select.onchange = () => explain(x, y, +select.value);
  span.append(select, ` of ${sample.count} (${rgbText(sample.color)})`);
  return span;
}

function hideRays() {
  page.explained = null;
  $("rays").hidden = true;
}

const rgbText = (c) => "[" + c.map((v) => v.toFixed(4)).join(", ") + "]";

function swatch(c) {
  const span = document.createElement("span");
  span.className = "swatch";
  const srgb = c.map((v) => Math.round(255 * Math.min(1, Math.max(0, v)) ** (1 / 2.2)));
  span.style.background = `rgb(${srgb.join(",")})`;
  return span;
}

function treeNode(n) {
  const li = document.createElement("li");
  const kind = document.createElement("span");
  kind.className = "kind-" + n.kind;
  kind.textContent = `${n.kind} ray`;
  li.append(kind, ` depth ${n.depth} `, swatch(n.color), ` ${rgbText(n.color)}`);
  const h = n.hit;
  if (!h) {
    li.append(" — missed: the background");
    return li;
  }
  const o = h.object;
  const where = o.line ? ` (line ${o.line})` : "";
  li.append(` — hit ${o.label || o.kind || "primitive " + o.primitive}${where} at t = ${h.t.toPrecision(5)}`);
  const list = document.createElement("ul");
  list.appendChild(termsItem(h.terms));
  for (const light of h.lights) {
    const item = document.createElement("li");
    item.className = "kind-shadow";
    item.textContent = `light ${light.index}: ${light.verdict}` +
      (light.blocked_by ? ` by ${light.blocked_by.label || light.blocked_by.kind}` : "") +
      `, diffuse ${rgbText(light.diffuse)}, specular ${rgbText(light.specular)}`;
    list.appendChild(item);
  }
  for (const child of h.children) {
    const item = treeNode(child);
    const symbol = child.kind === "reflected" ? "kr" : "kt";
    item.prepend(`${symbol} ${rgbText(child.coefficient)} × `);
    item.insertBefore(document.createTextNode(` = ${rgbText(child.contribution)}`), item.querySelector("ul"));
    list.appendChild(item);
  }
  for (const stop of h.stops) {
    const item = document.createElement("li");
    item.className = "stop";
    item.textContent = stop.reason === "tree_limit"
      ? `${stop.left_out} more rays and light verdicts traced from here are left out of the tree (it holds ${stop.max_rays})`
      : "stopped: " + stop.reason.replaceAll("_", " ");
    list.appendChild(item);
  }
  li.appendChild(list);
  return li;
}

// The local terms of the shading formula at a hit: the emission, the
// ambient term, the caustic map's light (when there is one) and the
// opacity that weighs them (when not 1); each light's follow.
function termsItem(t) {
  const item = document.createElement("li");
  item.className = "terms";
  const zero = (c) => c.every((v) => v === 0);
  let text = `terms: emission ${rgbText(t.emission)}, ambient ${rgbText(t.ambient)}`;
  if (t.caustic && !zero(t.caustic)) text += `, caustic ${rgbText(t.caustic)}`;
  if (!t.opacity.every((v) => v === 1)) text += `; opacity ${rgbText(t.opacity)} weighs them`;
  item.textContent = text;
  return item;
}
