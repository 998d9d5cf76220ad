// The CHAIN-geo 3D player: one level over the server's OpenEnv WebSocket session, played with
// the actions an agent has. Everything the server says is set as text (textContent), never as
// markup. Cells are 0-based lattice cells on the wire; action text is 1-based (the agent's).
import * as THREE from "./three.min.js";
import { FACES, cellsOf, cellsText, pieceObject } from "./geometry.js";
import { KEYS } from "./keys.js";

const body = document.body;
const STUDY = body.dataset.study === "1";
const params = new URLSearchParams(location.search);
const ui = {};
for (const el of document.querySelectorAll("[id]")) ui[el.id] = el;

const game = {
  ws: null, obs: null, scene: null, sent: [], agentView: false, level: body.dataset.level,
  selected: new Set(), cursor: 0, distance: "1", axis: "z", ghost: null, ghostIndex: -1,
  turnChoices: [], waiting: false, participant: null,
};

// ---------------------------------------------------------------------------------------------
// The session
// ---------------------------------------------------------------------------------------------

function connect() {
  const url = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws";
  const ws = new WebSocket(url);
  game.ws = ws;
  ws.onopen = () => reset();
  ws.onmessage = (ev) => receive(JSON.parse(ev.data));
  ws.onclose = () => say("Disconnected from the server; reload the page to play again.", true);
}

function resetData(images) {
  const data = { legal: "auto", scene: true, history: 5, images };
  if (STUDY) data.participant = game.participant;
  else data.level = game.level;
  return data;
}

function send(message) {
  game.waiting = true;
  game.ws.send(JSON.stringify(message));
}

function reset() {
  game.replay = [];
  send({ type: "reset", data: resetData(game.agentView) });
}

function act(text) {
  if (!text || game.waiting || !game.obs || game.obs.done) return;
  game.sent.push(text);
  send({ type: "step", data: { text } });
}

// Undo and the switch of views replay the episode: a new reset, then every action but the
// undone one (the server keeps no undo; the step counter shows the replayed steps).
function replayWith(actions, images) {
  game.replay = actions.slice();
  game.sent = [];
  send({ type: "reset", data: resetData(images) });
}

function receive(msg) {
  game.waiting = false;
  if (msg.type === "error") {
    say("Refused: " + (msg.data && msg.data.message), true);
    return;
  }
  if (msg.type !== "observation") return;
  const obs = msg.data.observation;
  obs.done = msg.data.done;
  if (game.replay && game.replay.length) {
    const next = game.replay.shift();
    game.sent.push(next);
    send({ type: "step", data: { text: next } });
    return;
  }
  show(obs);
}

// ---------------------------------------------------------------------------------------------
// What the page shows
// ---------------------------------------------------------------------------------------------

function say(text, bad) {
  ui.feedback.textContent = text;
  ui.feedback.className = bad ? "bad" : "";
}

function show(obs) {
  game.obs = obs;
  game.level = obs.level_id;
  ui.level.textContent = obs.level_id;
  ui.goal.textContent = obs.family + ": " + obs.instruction.split(".")[0] + ".";
  ui.steps.textContent = String(obs.steps);
  ui.budget.textContent = String(obs.max_steps);
  ui.optimal.textContent = obs.optimal_steps == null ? "hidden" : String(obs.optimal_steps);
  say(obs.feedback || "Your move.", obs.last && !obs.last.legal);
  ui.agenttext.textContent = obs.text + (obs.feedback ? "\n\nFeedback: " + obs.feedback : "");
  ui.agentimages.replaceChildren(
    ...Object.entries(obs.images || {}).map(([view, png]) => {
      const fig = document.createElement("figure");
      const img = document.createElement("img");
      img.src = "data:image/png;base64," + png;
      img.alt = view;
      const cap = document.createElement("figcaption");
      cap.textContent = view;
      fig.append(img, cap);
      return fig;
    }),
  );
  buildLegal(obs.legal || []);
  draw(obs.scene);
  ui.undo.disabled = STUDY || !game.sent.length;
  ui.solved.hidden = !obs.done;
  if (obs.done) {
    ui.solvedtitle.textContent = obs.success ? "Solved!" : "Episode over";
    let line = `${obs.steps} step${obs.steps === 1 ? "" : "s"}`;
    if (obs.optimal_steps != null) line += ` (fewest possible: ${obs.optimal_steps})`;
    ui.solvedsteps.textContent = line;
    ui.next.hidden = !STUDY;
  }
  body.dataset.state = obs.done ? (obs.success ? "solved" : "over") : "playing";
}

// The legal actions, indexed for the controls: placements by piece (as sorted cell keys),
// turns by group, axis and angle.
function buildLegal(legal) {
  game.places = new Map();
  game.turns = new Map();
  for (const text of legal) {
    const words = text.split(" ");
    if (words[0] === "place") {
      const list = game.places.get(words[1]) || [];
      list.push(cellsOf(text.slice(text.indexOf("("))));
      game.places.set(words[1], list);
    } else if (words[0] === "rotate") {
      const key = words.slice(1, 4).join(" ");
      game.turns.set(key, [...(game.turns.get(key) || []), text]);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The 3D scene
// ---------------------------------------------------------------------------------------------

const renderer = new THREE.WebGLRenderer({ canvas: ui.canvas, antialias: true, preserveDrawingBuffer: true });
const scene3 = new THREE.Scene();
scene3.background = new THREE.Color(0xf4f4f0);
const camera = new THREE.PerspectiveCamera(40, 1, 0.1, 1000);
camera.up.set(0, 0, 1);
const controls = new THREE.OrbitControls(camera, ui.canvas);
controls.addEventListener("change", render);
scene3.add(new THREE.AmbientLight(0xffffff, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(2, -3, 4);
scene3.add(sun);
const world = new THREE.Group();
scene3.add(world);
const meshes = new Map();
let framed = false;

function draw(sceneData) {
  if (!sceneData) return;
  game.scene = sceneData;
  world.clear();
  meshes.clear();
  ui.labels.replaceChildren();
  for (const p of sceneData.pieces) {
    const mesh = pieceObject(p.cells, p.rgb, 1);
    mesh.userData.piece = p.name;
    world.add(mesh);
    const label = document.createElement("span");
    label.className = "label";
    label.textContent = p.name;
    ui.labels.append(label);
    meshes.set(p.name, { mesh, piece: p, label });
  }
  if (sceneData.box) {
    const [a, b, c] = sceneData.box;
    const box = new THREE.LineSegments(
      new THREE.EdgesGeometry(new THREE.BoxGeometry(a, b, c)),
      new THREE.LineBasicMaterial({ color: 0x555555 }),
    );
    box.position.set(a / 2, b / 2, c / 2);
    world.add(box);
  }
  const names = sceneData.pieces.map((p) => p.name);
  game.selected = new Set([...game.selected].filter((n) => names.includes(n)));
  game.cursor = Math.min(game.cursor, names.length - 1);
  if (!framed) frame();
  for (const b of [ui.turnplus, ui.turnminus]) b.hidden = !sceneData.turns && !sceneData.box;
  pieceList();
  updateGhost();
  render();
}

function frame() {
  const lo = [Infinity, Infinity, Infinity];
  const hi = [-Infinity, -Infinity, -Infinity];
  const cells = game.scene.pieces.flatMap((p) => p.cells);
  if (game.scene.box) cells.push([0, 0, 0], game.scene.box.map((v) => v - 1));
  for (const c of cells) for (let i = 0; i < 3; i++) { lo[i] = Math.min(lo[i], c[i]); hi[i] = Math.max(hi[i], c[i] + 1); }
  const centre = new THREE.Vector3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  const size = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  controls.target.copy(centre);
  camera.position.set(centre.x + 0.9 * size, centre.y - 1.5 * size, centre.z + 1.1 * size);
  controls.update();
  framed = true;
}

function resize() {
  const w = ui.canvas.clientWidth;
  const h = ui.canvas.clientHeight;
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(1, h);
  camera.updateProjectionMatrix();
  render();
}

// A label sits on the piece's cell farthest from the middle of the scene, so labels of pieces
// that cross in the middle do not pile up.
function labelCell(cells) {
  const t = controls.target;
  let best = cells[0];
  let far = -1;
  for (const c of cells) {
    const d = (c[0] + 0.5 - t.x) ** 2 + (c[1] + 0.5 - t.y) ** 2 + (c[2] + 0.5 - t.z) ** 2;
    if (d > far) { far = d; best = c; }
  }
  return best;
}

function render() {
  for (const { mesh, piece, label } of meshes.values()) {
    const on = game.selected.has(piece.name);
    mesh.material.emissive.setHex(on ? 0x555555 : 0x000000);
    const c = labelCell(piece.cells);
    const p = new THREE.Vector3(c[0] + 0.5, c[1] + 0.5, c[2] + 0.5).project(camera);
    label.style.left = `${((p.x + 1) / 2) * ui.canvas.clientWidth}px`;
    label.style.top = `${((1 - p.y) / 2) * ui.canvas.clientHeight}px`;
    label.classList.toggle("on", on);
    label.classList.toggle("cursor", names()[game.cursor] === piece.name);
  }
  renderer.render(scene3, camera);
}

// ---------------------------------------------------------------------------------------------
// Picking, the selection and the stacking ghost
// ---------------------------------------------------------------------------------------------

const raycaster = new THREE.Raycaster();

function hitAt(x, y) {
  const r = ui.canvas.getBoundingClientRect();
  const v = new THREE.Vector2(((x - r.left) / r.width) * 2 - 1, -((y - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(v, camera);
  const hit = raycaster.intersectObjects([...meshes.values()].map((m) => m.mesh), false)[0];
  return hit ? hit.object.userData.piece : null;
}

function names() {
  return game.scene ? game.scene.pieces.map((p) => p.name) : [];
}

function pieceOf(name) {
  return game.scene.pieces.find((p) => p.name === name);
}

function select(name, how) {
  if (!name) return;
  game.cursor = names().indexOf(name);
  const p = pieceOf(name);
  if (how === "toggle") {
    if (game.selected.has(name)) game.selected.delete(name);
    else game.selected.add(name);
  } else if (how === "part" && p.part != null) {
    game.selected = new Set(game.scene.pieces.filter((q) => q.part === p.part).map((q) => q.name));
  } else {
    game.selected = new Set([name]);
  }
  game.ghostIndex = -1;
  game.ghost = null;
  updateGhost();
  pieceList();
  render();
}

function group() {
  return [...game.selected].sort().join("+");
}

function stackingPiece() {
  if (game.obs.family !== "stacking" || game.selected.size !== 1) return null;
  const p = pieceOf([...game.selected][0]);
  return p && p.place === "tray" ? p : null;
}

function updateGhost() {
  if (game.ghostMesh) { world.remove(game.ghostMesh); game.ghostMesh = null; }
  const p = game.obs && game.scene ? stackingPiece() : null;
  if (!p) { ui.ghost.textContent = ""; return; }
  if (!game.ghost) {
    const legal = game.places.get(p.name) || [];
    game.ghost = legal.length ? legal[0].map((c) => c.slice()) : p.shape.map((c) => c.slice());
    game.ghostIndex = legal.length ? 0 : -1;
  }
  const ok = isLegalPlace(p.name, game.ghost);
  game.ghostMesh = pieceObject(game.ghost, p.rgb, 0.55);
  game.ghostMesh.children[0].material.color.setHex(ok ? 0x00aa00 : 0xcc0000);
  world.add(game.ghostMesh);
  ui.ghost.textContent = `place ${p.name} ${cellsText(game.ghost)}` + (ok ? "  (fits)" : "  (does not fit here)");
}

function isLegalPlace(name, cells) {
  const key = cellsText(cells);
  return (game.places.get(name) || []).some((c) => cellsText(c) === key);
}

function moveGhost(axis, sign) {
  game.ghost = game.ghost.map((c) => c.map((v, i) => (i === axis ? v + sign : v)));
  updateGhost();
  render();
}

function turnGhost(axis) {
  const lo = [0, 1, 2].map((i) => Math.min(...game.ghost.map((c) => c[i])));
  const turned = game.ghost.map(([x, y, z]) =>
    axis === 0 ? [x, -z, y] : axis === 1 ? [z, y, -x] : [-y, x, z]);
  const tlo = [0, 1, 2].map((i) => Math.min(...turned.map((c) => c[i])));
  game.ghost = turned.map((c) => c.map((v, i) => v - tlo[i] + lo[i]));
  updateGhost();
  render();
}

function cyclePlacement(step) {
  const p = stackingPiece();
  const legal = p ? game.places.get(p.name) || [] : [];
  if (!legal.length) return;
  game.ghostIndex = (game.ghostIndex + step + legal.length) % legal.length;
  game.ghost = legal[game.ghostIndex].map((c) => c.slice());
  updateGhost();
  render();
}

// ---------------------------------------------------------------------------------------------
// Actions
// ---------------------------------------------------------------------------------------------

const DIRS = { d: "+x", a: "-x", w: "+y", s: "-y", e: "+z", q: "-z" };

function direction(dir) {
  if (!game.obs || !game.selected.size) { say("Select a piece first (click it, or ] and [).", true); return; }
  if (game.obs.family === "stacking") {
    if (stackingPiece()) moveGhost("xyz".indexOf(dir[1]), dir[0] === "+" ? 1 : -1);
    return;
  }
  const text = `move ${group()} ${dir} ${game.distance}`;
  setDistance("1");
  act(text);
}

function setDistance(d) {
  game.distance = d;
  ui.distance.textContent = d === "inf" ? "∞ (out)" : d;
}

function turn(angle) {
  if (game.obs.family === "stacking") { if (stackingPiece()) turnGhost("xyz".indexOf(game.axis)); return; }
  if (!game.scene.turns) { say("This level's rules allow no turns.", true); return; }
  if (!game.selected.size) { say("Select a piece first.", true); return; }
  const key = `${group()} ${game.axis} ${angle}`;
  const legal = game.turns.get(key) || [];
  if (legal.length <= 1) { act(legal[0] || `rotate ${key}`); return; }
  game.turnChoices = legal;
  ui.choices.replaceChildren(...legal.map((text, i) => {
    const b = document.createElement("button");
    b.textContent = `${i + 1}: ${text}`;
    b.onclick = () => { ui.choices.replaceChildren(); act(text); };
    return b;
  }));
  say("Several centres work for that turn: pick one (or press its number).");
}

function place() {
  const p = stackingPiece();
  if (p && game.ghost) act(`place ${p.name} ${cellsText(game.ghost)}`);
}

function pickup() {
  if (game.selected.size === 1) act(`pickup ${[...game.selected][0]}`);
}

function undo() {
  if (STUDY || !game.sent.length || game.waiting) return;
  replayWith(game.sent.slice(0, -1), game.agentView);
}

function toggleView() {
  if (STUDY && game.obs && game.obs.steps > 0) { say("In a study the view is chosen before the first step.", true); return; }
  game.agentView = !game.agentView;
  body.classList.toggle("agent", game.agentView);
  replayWith(game.sent, game.agentView);
}

function pieceList() {
  ui.pieces.replaceChildren(...names().map((name, i) => {
    const p = pieceOf(name);
    const li = document.createElement("li");
    const sw = document.createElement("span");
    sw.className = "swatch";
    sw.style.background = p.rgb;
    const t = document.createElement("span");
    t.textContent = `${name} (${p.place}${p.part != null ? " " + p.part : ""})`;
    li.append(sw, t);
    li.classList.toggle("on", game.selected.has(name));
    li.classList.toggle("cursor", i === game.cursor);
    li.onclick = (ev) => select(name, ev.shiftKey ? "toggle" : "one");
    return li;
  }));
}

// The cursor only points; space adds or removes the piece it points at.
function moveCursor(step) {
  const all = names();
  if (!all.length) return;
  game.cursor = (game.cursor + step + all.length) % all.length;
  pieceList();
  render();
}

function legend() {
  ui.keys.replaceChildren(...KEYS.map(([k, what]) => {
    const tr = document.createElement("tr");
    const a = document.createElement("td");
    const b = document.createElement("td");
    a.textContent = k;
    b.textContent = what;
    tr.append(a, b);
    return tr;
  }));
}

function onKey(ev) {
  if (ev.target === ui.typed || !game.obs) return;
  const k = ev.key;
  if (game.turnChoices.length && /^[1-9]$/.test(k) && +k <= game.turnChoices.length) {
    const text = game.turnChoices[+k - 1];
    game.turnChoices = [];
    ui.choices.replaceChildren();
    act(text);
  } else if (k in DIRS) direction(DIRS[k]);
  else if (/^[1-9]$/.test(k)) setDistance(k);
  else if (k === "0" || k === "i") setDistance("inf");
  else if (k === "]") moveCursor(1);
  else if (k === "[") moveCursor(-1);
  else if (k === " ") select(names()[game.cursor], "toggle");
  else if (k === "g") select(names()[game.cursor], "part");
  else if (k === "x" || k === "y" || k === "z") { game.axis = k; ui.axis.textContent = k; }
  else if (k === "r") turn("+90");
  else if (k === "f") turn("-90");
  else if (k === "F") act("finish");
  else if (k === "n") cyclePlacement(1);
  else if (k === "b") cyclePlacement(-1);
  else if (k === "Enter") place();
  else if (k === "p") pickup();
  else if (k === "u") undo();
  else if (k === "v") toggleView();
  else if (k === "Escape") { game.selected.clear(); game.ghost = null; updateGhost(); pieceList(); render(); }
  else if (k.startsWith("Arrow")) orbit(k);
  else if (k === "+" || k === "=") zoom(0.85);
  else if (k === "-") zoom(1 / 0.85);
  else return;
  ev.preventDefault();
}

function orbit(k) {
  const off = camera.position.clone().sub(controls.target);
  const angle = (k === "ArrowLeft" ? 1 : k === "ArrowRight" ? -1 : 0) * 0.2;
  off.applyAxisAngle(new THREE.Vector3(0, 0, 1), angle);
  if (k === "ArrowUp" || k === "ArrowDown") off.z += (k === "ArrowUp" ? 1 : -1) * 0.15 * off.length();
  camera.position.copy(controls.target).add(off);
  controls.update();
}

function zoom(f) {
  const off = camera.position.clone().sub(controls.target).multiplyScalar(f);
  camera.position.copy(controls.target).add(off);
  controls.update();
}

// ---------------------------------------------------------------------------------------------
// Wiring
// ---------------------------------------------------------------------------------------------

ui.canvas.addEventListener("click", (ev) => { const n = hitAt(ev.clientX, ev.clientY); if (n) select(n, ev.shiftKey ? "toggle" : "one"); });
ui.canvas.addEventListener("dblclick", (ev) => select(hitAt(ev.clientX, ev.clientY), "part"));
document.addEventListener("keydown", onKey);
for (const [k, dir] of Object.entries(DIRS)) {
  const b = document.createElement("button");
  b.textContent = `${dir} (${k})`;
  b.onclick = () => direction(dir);
  ui.dirs.append(b);
}
ui.inf.onclick = () => setDistance("inf");
ui.one.onclick = () => setDistance("1");
ui.turnplus.onclick = () => turn("+90");
ui.turnminus.onclick = () => turn("-90");
ui.place.onclick = place;
ui.pickup.onclick = pickup;
ui.finish.onclick = () => act("finish");
ui.undo.onclick = undo;
ui.view.onclick = toggleView;
ui.next.onclick = () => { ui.solved.hidden = true; game.sent = []; framed = false; reset(); };
ui.typedform.onsubmit = (ev) => { ev.preventDefault(); act(ui.typed.value.trim()); ui.typed.value = ""; };
window.addEventListener("resize", resize);
legend();
setDistance("1");

// Read-only hooks for the tests: where a piece can be clicked, and what the page holds. Every
// action still goes through real input events.
window.chainPlayer = {
  pointOf(name) {
    const m = meshes.get(name);
    if (!m) return null;
    const r = ui.canvas.getBoundingClientRect();
    for (const c of m.piece.cells) {
      for (const [n] of FACES) {
        const p = new THREE.Vector3(c[0] + 0.5 + 0.45 * n[0], c[1] + 0.5 + 0.45 * n[1], c[2] + 0.5 + 0.45 * n[2]).project(camera);
        const x = Math.round(r.left + ((p.x + 1) / 2) * r.width);
        const y = Math.round(r.top + ((1 - p.y) / 2) * r.height);
        if (x - 2 <= r.left || x + 2 >= r.right || y - 2 <= r.top || y + 2 >= r.bottom) continue;
        // a point whose neighbours hit the same piece: a click there cannot land on another
        const around = [[0, 0], [-2, 0], [2, 0], [0, -2], [0, 2]];
        if (around.every(([dx, dy]) => hitAt(x + dx, y + dy) === name)) return [x, y];
      }
    }
    return null;
  },
  status() {
    return {
      steps: game.obs ? game.obs.steps : null, done: game.obs ? game.obs.done : false,
      success: game.obs ? game.obs.success : false, waiting: game.waiting, level: game.level,
      selected: [...game.selected].sort(), cursor: names()[game.cursor] || null,
      ghost: game.ghost ? cellsText(game.ghost) : null, distance: game.distance, axis: game.axis,
      names: names(), sent: game.sent.slice(), choices: game.turnChoices.slice(),
    };
  },
};

function start() {
  if (STUDY) {
    const given = params.get("participant");
    let id = given || localStorage.getItem("chain-participant");
    if (!id) {
      const a = new Uint8Array(6);
      crypto.getRandomValues(a);
      id = "p" + [...a].map((v) => v.toString(16).padStart(2, "0")).join("");
    }
    localStorage.setItem("chain-participant", id);
    game.participant = id;
    ui.participant.textContent = id;
  }
  resize();
  connect();
}

start();
