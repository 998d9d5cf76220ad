// The run viewer's behaviour: sortable tables and the episode stepper (with a play button
// that steps on by itself, pause and speed). Pages are complete
// without it (every turn is shown, tables in their written order); this script only
// rearranges and hides what the server already escaped. It never writes HTML: text goes in
// through textContent, so nothing from a log can become markup here either.
//
// The URL drives both: "#sort=TABLE.COLUMN&dir=asc|desc" and "#step=N" (1-based). A
// "?selftest=ACTIONS" query (comma-separated "sort:TABLE.COLUMN", "click:ID", "key:KEY")
// dispatches real click and keydown events, so a headless browser exercises the same
// handlers a person does; after each action "ACTION STATE" (STATE: JSON of what is shown)
// is appended to <pre id="selftest">.
"use strict";
(function () {
  function params(text) {
    var out = {};
    text.replace(/^[#?]/, "").split("&").forEach(function (part) {
      var i = part.indexOf("=");
      if (i > 0) out[decodeURIComponent(part.slice(0, i))] = decodeURIComponent(part.slice(i + 1));
    });
    return out;
  }

  function setHash(hash) {
    try {
      history.replaceState(null, "", hash);
    } catch (e) {
      /* some file:// setups refuse; the page still works */
    }
  }

  // ---- sortable tables --------------------------------------------------------------------
  // Cells carry their raw value in data-sort ("" = no value, always last); columns whose
  // header says data-type="num" compare numerically, others as text. The sort is stable, so
  // ties keep the order the report wrote.
  function sortTable(table, col, dir) {
    var th = table.tHead.rows[0].cells[col];
    if (!th) return;
    var numeric = th.getAttribute("data-type") === "num";
    var body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var sign = dir === "desc" ? -1 : 1;
    function key(row) {
      var cell = row.cells[col];
      var raw = cell ? cell.getAttribute("data-sort") : "";
      if (raw === null) raw = cell.textContent;
      return raw;
    }
    rows.sort(function (a, b) {
      var x = key(a), y = key(b);
      if (x === "" || y === "") return (x === "") - (y === "");
      if (numeric) return sign * (parseFloat(x) - parseFloat(y));
      return sign * (x < y ? -1 : x > y ? 1 : 0);
    });
    rows.forEach(function (row) { body.appendChild(row); });
    Array.prototype.forEach.call(table.tHead.rows[0].cells, function (cell) {
      cell.removeAttribute("aria-sort");
    });
    th.setAttribute("aria-sort", dir === "desc" ? "descending" : "ascending");
  }

  function onSortClick(event) {
    var th = event.currentTarget.closest("th");
    var table = th.closest("table");
    var dir = th.getAttribute("aria-sort") === "ascending" ? "desc" : "asc";
    sortTable(table, th.cellIndex, dir);
    setHash("#sort=" + encodeURIComponent(table.id) + "." + th.cellIndex + "&dir=" + dir);
  }

  // ---- episode stepper --------------------------------------------------------------------
  var viewer = document.getElementById("viewer");
  var frames = viewer ? viewer.querySelectorAll(".frame") : [];
  var current = 0;

  function show(index) {
    if (!frames.length) return;
    current = Math.max(0, Math.min(frames.length - 1, index));
    Array.prototype.forEach.call(frames, function (frame, i) {
      frame.hidden = i !== current;
    });
    viewer.setAttribute("data-current", String(current + 1));
    document.getElementById("position").textContent =
      frames[current].getAttribute("data-label") + " (" + (current + 1) + " of " + frames.length + ")";
    document.getElementById("prev").disabled = current === 0;
    document.getElementById("first").disabled = current === 0;
    document.getElementById("next").disabled = current === frames.length - 1;
    document.getElementById("last").disabled = current === frames.length - 1;
    setHash("#step=" + (current + 1));
  }

  // ---- play: one step every STEP_MS / speed, pausing at the last step ----------------------
  var STEP_MS = 1500;
  var timer = null;

  function speed() {
    var select = document.getElementById("speed");
    var value = select ? parseFloat(select.value) : 1;
    return value > 0 ? value : 1;
  }

  function setPlaying(on) {
    if (timer !== null) clearInterval(timer);
    timer = null;
    if (on) {
      if (current === frames.length - 1) show(0);  // played to the end: start again
      timer = setInterval(tick, STEP_MS / speed());
    }
    var button = document.getElementById("play");
    button.setAttribute("aria-pressed", on ? "true" : "false");
    button.textContent = on ? "\u275A\u275A Pause" : "\u25B6 Play";
    viewer.setAttribute("data-playing", on ? "yes" : "no");
  }

  function tick() {
    show(current + 1);
    if (current === frames.length - 1) setPlaying(false);
  }

  function step(index) {
    // a person taking a step by hand takes over from the player
    if (timer !== null) setPlaying(false);
    show(index);
  }

  function onKey(event) {
    if (!frames.length || event.altKey || event.ctrlKey || event.metaKey) return;
    var tag = event.target && event.target.tagName;
    if (tag === "INPUT" || tag === "TEXTAREA" || tag === "SELECT" || tag === "BUTTON") return;
    if (event.key === "ArrowRight") step(current + 1);
    else if (event.key === "ArrowLeft") step(current - 1);
    else if (event.key === "Home") step(0);
    else if (event.key === "End") step(frames.length - 1);
    else if (event.key === " ") setPlaying(timer === null);
    else return;
    event.preventDefault();
  }

  function fromHash() {
    var p = params(location.hash);
    if (p.sort) {
      var dot = p.sort.lastIndexOf(".");
      var table = document.getElementById(p.sort.slice(0, dot));
      if (table && table.tHead) sortTable(table, parseInt(p.sort.slice(dot + 1), 10), p.dir);
    }
    if (frames.length) show(p.step ? parseInt(p.step, 10) - 1 || 0 : current);
  }

  Array.prototype.forEach.call(document.querySelectorAll("table.sortable th button"), function (b) {
    b.addEventListener("click", onSortClick);
  });
  if (frames.length) {
    viewer.classList.add("stepping");
    document.getElementById("first").addEventListener("click", function () { step(0); });
    document.getElementById("prev").addEventListener("click", function () { step(current - 1); });
    document.getElementById("next").addEventListener("click", function () { step(current + 1); });
    document.getElementById("last").addEventListener("click", function () {
      step(frames.length - 1);
    });
    document.getElementById("play").addEventListener("click", function () {
      setPlaying(timer === null);
    });
    document.getElementById("speed").addEventListener("change", function () {
      if (timer !== null) setPlaying(true);  // the new pace from now on
    });
    document.addEventListener("keydown", onKey);
  }
  window.addEventListener("hashchange", fromHash);
  fromHash();

  // ---- self-test hook -----------------------------------------------------------------------
  var test = params(location.search).selftest;
  if (!test) return;
  var log = document.createElement("pre");
  log.id = "selftest";
  document.body.appendChild(log);
  function state() {
    // JSON, one line: {"step": N, "playing": B} on an episode, {"TABLE": [first cells...]}
    // elsewhere.
    var out = {};
    if (frames.length) {
      out.step = parseInt(viewer.getAttribute("data-current"), 10);
      out.playing = timer !== null;
    }
    Array.prototype.forEach.call(document.querySelectorAll("table.sortable"), function (t) {
      out[t.id] = Array.prototype.map.call(t.tBodies[0].rows, function (r) {
        return r.cells[0].textContent;
      });
    });
    return JSON.stringify(out);
  }
  log.textContent = "start " + state() + "\n";
  var actions = test.split(",");
  var finished = { actions: false, load: false };
  function done(what) {
    finished[what] = true;
    if (finished.actions && finished.load) log.setAttribute("data-done", "yes");
  }
  function run(i) {
    // one action after another; "wait:MS" resumes on the page's clock
    for (; i < actions.length; i++) {
      var action = actions[i];
      var at = action.indexOf(":");
      var kind = action.slice(0, at), arg = action.slice(at + 1);
      if (kind === "wait") {
        setTimeout(function () {
          log.textContent += action + " " + state() + "\n";
          run(i + 1);
        }, parseInt(arg, 10) || 0);
        return;
      }
      if (!perform(kind, arg)) {
        log.textContent += "missing " + action + "\n";
        continue;
      }
      log.textContent += action + " " + state() + "\n";
    }
    done("actions");
  }
  function perform(kind, arg) {
    var target = null;
    if (kind === "sort") {
      var dot = arg.lastIndexOf(".");
      var table = document.getElementById(arg.slice(0, dot));
      var th = table && table.tHead.rows[0].cells[parseInt(arg.slice(dot + 1), 10)];
      target = th && th.querySelector("button");
    } else if (kind === "click") {
      target = document.getElementById(arg);
    } else if (kind === "select") {
      var eq = arg.indexOf("=");
      var select = document.getElementById(arg.slice(0, eq));
      if (!select) return false;
      select.value = arg.slice(eq + 1);
      select.dispatchEvent(new Event("change", { bubbles: true }));
      return true;
    }
    if (kind === "key") {
      document.body.dispatchEvent(
        new KeyboardEvent("keydown", { key: arg === "Space" ? " " : arg, bubbles: true }));
      return true;
    }
    if (!target) return false;
    target.dispatchEvent(new MouseEvent("click", { bubbles: true, cancelable: true }));
    return true;
  }
  run(0);
  window.addEventListener("load", function () {
    // Only the images on screen: hidden turns load theirs lazily, when shown.
    var images = Array.prototype.filter.call(document.querySelectorAll("img"), function (img) {
      return img.getClientRects().length > 0;
    });
    var loaded = images.filter(function (img) { return img.complete && img.naturalWidth > 0; });
    log.setAttribute("data-images", loaded.length + "/" + images.length);
    done("load");
  });
})();
