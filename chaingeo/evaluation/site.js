// The run viewer's behaviour: sortable tables and the episode stepper. Pages are complete
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

  function onKey(event) {
    if (!frames.length || event.altKey || event.ctrlKey || event.metaKey) return;
    var tag = event.target && event.target.tagName;
    if (tag === "INPUT" || tag === "TEXTAREA" || tag === "SELECT") return;
    if (event.key === "ArrowRight") show(current + 1);
    else if (event.key === "ArrowLeft") show(current - 1);
    else if (event.key === "Home") show(0);
    else if (event.key === "End") show(frames.length - 1);
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
    document.getElementById("first").addEventListener("click", function () { show(0); });
    document.getElementById("prev").addEventListener("click", function () { show(current - 1); });
    document.getElementById("next").addEventListener("click", function () { show(current + 1); });
    document.getElementById("last").addEventListener("click", function () {
      show(frames.length - 1);
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
    // JSON, one line: {"step": N} on an episode, {"TABLE": [first cells...]} elsewhere.
    var out = {};
    if (frames.length) out.step = parseInt(viewer.getAttribute("data-current"), 10);
    Array.prototype.forEach.call(document.querySelectorAll("table.sortable"), function (t) {
      out[t.id] = Array.prototype.map.call(t.tBodies[0].rows, function (r) {
        return r.cells[0].textContent;
      });
    });
    return JSON.stringify(out);
  }
  log.textContent = "start " + state() + "\n";
  test.split(",").forEach(function (action) {
    var i = action.indexOf(":");
    var kind = action.slice(0, i), arg = action.slice(i + 1);
    var target = null;
    if (kind === "sort") {
      var dot = arg.lastIndexOf(".");
      var table = document.getElementById(arg.slice(0, dot));
      var th = table && table.tHead.rows[0].cells[parseInt(arg.slice(dot + 1), 10)];
      target = th && th.querySelector("button");
    } else if (kind === "click") {
      target = document.getElementById(arg);
    }
    if (kind === "key") {
      document.body.dispatchEvent(new KeyboardEvent("keydown", { key: arg, bubbles: true }));
    } else if (target) {
      target.dispatchEvent(new MouseEvent("click", { bubbles: true, cancelable: true }));
    } else {
      log.textContent += "missing " + action + "\n";
      return;
    }
    log.textContent += action + " " + state() + "\n";
  });
  window.addEventListener("load", function () {
    // Only the images on screen: hidden turns load theirs lazily, when shown.
    var images = Array.prototype.filter.call(document.querySelectorAll("img"), function (img) {
      return img.getClientRects().length > 0;
    });
    var loaded = images.filter(function (img) { return img.complete && img.naturalWidth > 0; });
    log.setAttribute("data-images", loaded.length + "/" + images.length);
    log.setAttribute("data-done", "yes");
  });
})();
