// The task page: follows the task's events and draws the robot's map as it grows.
"use strict";

(() => {
  const { el, json } = AVS;
  const $ = (id) => document.getElementById(id);
  const taskId = decodeURIComponent(window.location.pathname.split("/").filter(Boolean).pop() || "");
  const base = `/v1/tasks/${encodeURIComponent(taskId)}`;

  // what the browser tests read: when each event was shown (ms since the epoch, by seq) and
  // when the page had shown everything of a finished task (ms since navigation start)
  // (`sent`: the service's own time stamp of the event, when it has one)
  const page = {
    taskId, shown: {}, sent: {}, events: 0, batches: 0, complete: null, stream: "connecting",
    model: () => ({
      places: M.places.length, placeholders: M.placeholders.length, rooms: Object.keys(M.rooms).length,
      path: M.path.length, grid: Boolean(M.image), cones: M.cones.length, plan: plan ? plan.steps.length : 0,
    }),
  };
  window.avsPage = page;

  const COLOURS = {
    corridor: "#1f77b4", kitchen: "#d62728", office: "#2ca02c", meeting_room: "#9467bd",
    living_room: "#ff7f0e", bathroom: "#17becf",
  };
  const EXTRA = ["#8c564b", "#e377c2", "#bcbd22", "#7f7f7f", "#393b79", "#637939"];
  function colour(category) {
    if (!category) return "#999999";
    if (!COLOURS[category]) {
      let h = 0;
      for (const ch of category) h = (h * 31 + ch.charCodeAt(0)) >>> 0;
      COLOURS[category] = EXTRA[h % EXTRA.length];
    }
    return COLOURS[category];
  }
  function rgb(hex) {
    const n = parseInt(hex.slice(1), 16);
    return [(n >> 16) & 255, (n >> 8) & 255, n & 255];
  }

  // ---- the model, built from the events -------------------------------------------------

  let M;
  let plan = null;
  let state = "";
  let outcome = null;
  let form = null; // the task's form (GET /v1/tasks/ID: `task`)
  let targets = null; // a task of several: each label's part (AVS_TARGETS)
  let taskStart = 0; // the simulated time of the `task` event
  let building = null; // the task's building (request), if any
  let memoryEvents = []; // the trace's `memory` events (what was recalled, checked, dropped)
  let memoryPart = null; // the summary's `memory` and `experience` parts, once it ended
  let experiencePart = null;
  let memoryDirty = false;
  function reset() {
    M = {
      grid: null, image: null, tinted: null, known: null, places: [], placeholders: [],
      doors: [], rooms: {}, objects: [], blocked: [], path: [], detections: [],
      observations: [], pose: null, cones: [], t: 0,
    };
    plan = null;
    outcome = null;
    targets = null;
    memoryEvents = [];
  }
  reset();

  let gridDirty = false;
  let tintDirty = false;
  let planDirty = false;
  let targetsDirty = false;
  let decoding = 0;
  let drawPending = false;
  let unstamped = [];

  function apply(e) {
    switch (e.type) {
      case "state":
        if (e.state === "running" && (e.attempt || 1) > 1) {
          reset(); // a requeued task runs again from the start
          gridDirty = tintDirty = planDirty = targetsDirty = memoryDirty = true;
        }
        state = e.state;
        break;
      case "start":
        if (e.pose) M.pose = e.pose;
        break;
      case "map":
        applyMap(e);
        break;
      case "cones":
        M.cones.push({ ...e, result: null });
        break;
      case "dt": {
        const set = [...M.cones].reverse().find((c) => c.label === e.label && c.location === e.location);
        if (set) set.result = e.result;
        break;
      }
      case "plan":
        plan = { ...e, steps: e.plan || [], done: new Set(), current: -1 };
        planDirty = true;
        break;
      case "action":
        onAction(e);
        break;
      case "observation":
        if (Array.isArray(e.position)) M.observations.push([e.position[0], e.position[1], e.label, Boolean(e.detected)]);
        break;
      case "done":
        outcome = { outcome: e.outcome, reason: e.reason };
        break;
      case "task":
        taskStart = typeof e.t === "number" ? e.t : 0;
        targets = AVS_TARGETS.open(e.targets || []);
        targetsDirty = true;
        break;
      case "memory":
        memoryEvents.push(e);
        memoryDirty = true;
        break;
      case "turn":
      case "target":
        if (targets) {
          AVS_TARGETS.apply(targets, e, M.objects, taskStart);
          targetsDirty = true;
        }
        break;
      default:
        break;
    }
    if (typeof e.t === "number") M.t = e.t;
  }

  function applyMap(e) {
    if (e.pose) M.pose = e.pose;
    if (e.grid) {
      M.grid = e.grid;
      gridDirty = true;
    }
    for (const part of ["places", "placeholders", "doors", "rooms", "objects", "blocked"]) {
      if (part in e) {
        M[part] = e[part];
        if (part === "places" || part === "rooms") tintDirty = true;
      }
    }
    if (Array.isArray(e.path)) {
      M.path.length = Math.min(M.path.length, e.path_from || 0);
      M.path.push(...e.path);
    }
    if (Array.isArray(e.detections)) {
      M.detections.length = Math.min(M.detections.length, e.detections_from || 0);
      M.detections.push(...e.detections);
    }
  }

  function onAction(e) {
    if (!plan || !e.status) return;
    const i = plan.steps.findIndex((s, k) => s === e.action && !plan.done.has(k));
    if (i < 0) return;
    if (e.status === "start") plan.current = i;
    else {
      plan.done.add(i);
      if (plan.current === i) plan.current = -1;
    }
    planDirty = true;
  }

  // ---- the side panel -------------------------------------------------------------------

  function describe(e) {
    const n = (v, d = 3) => (typeof v === "number" ? Number(v.toFixed(d)) : v);
    switch (e.type) {
      case "state": return `${e.state}${e.attempt ? ` (attempt ${e.attempt})` : ""}${e.message ? `: ${e.message}` : ""}`;
      case "start": return `${e.robot} in ${e.world}, looking for ${e.target} (${e.strategy})`;
      case "plan": return `${e.why}: ${e.status}, ${(e.plan || []).length} steps` +
        (e.probability !== undefined ? `, p=${n(e.probability)}, cost ${n(e.cost, 1)}` : "");
      case "action": return `${e.action}${e.status ? ` ${e.status}` : ""}${e.detail ? `: ${e.detail}` : ""}`;
      case "observation": return `${e.label} ${e.detected ? "seen" : "not seen"}${e.watching ? " (on the way)" : ""}`;
      case "map": {
        const parts = ["grid", "places", "placeholders", "doors", "rooms", "objects"].filter((k) => k in e);
        return `map at (${n(e.pose[0], 2)}, ${n(e.pose[1], 2)})${parts.length ? `: ${parts.join(", ")}` : ""}`;
      }
      case "cones": return `${e.cones.length} view cones for ${e.label} ${e.relation} ${e.location}`;
      case "dt": return `search ${e.label} ${e.relation} ${e.location}: ${e.result} (p=${n(e.probability)})`;
      case "replan": return `${e.status}${e.action ? ` ${e.action}` : ""}${e.detail ? `: ${e.detail}` : ""}`;
      case "done": return `${e.outcome}: ${e.reason}`;
      case "task": return `${(e.targets || []).join(", ")}: mode ${e.mode}, count ${e.count}` +
        (e.stop_below !== null && e.stop_below !== undefined ? `, stop below ${e.stop_below}` : "");
      case "turn": return `${e.target} ${e.status}` + (e.status === "start"
        ? ((e.watch || []).length ? `, also watching for ${e.watch.join(", ")}` : "")
        : `: ${e.outcome}${e.reason ? ` (${e.reason})` : ""}`);
      case "target": return `${e.target}: ${e.outcome}${e.reason ? `: ${e.reason}` : ""}`;
      case "memory": return AVS_MEMORY.describe(e);
      default: {
        const { t, wall, type, seq, retry, ...rest } = e;
        const text = JSON.stringify(rest);
        return text.length > 160 ? `${text.slice(0, 157)}...` : text;
      }
    }
  }

  const MAX_LOG = 1500;
  function renderLog(batch) {
    const list = $("events");
    const fragment = document.createDocumentFragment();
    for (const e of batch) {
      const t = typeof e.t === "number" ? `${e.t.toFixed(1)} s` : "";
      fragment.append(el("li", { "data-seq": e.seq, class: `ev ev-${e.type}` },
        el("span", { class: "t", text: t }), el("b", { text: e.type }), " ", describe(e)));
    }
    list.append(fragment);
    while (list.childElementCount > MAX_LOG) list.firstElementChild.remove();
    $("event-count").textContent = String(page.events);
    list.scrollTop = list.scrollHeight;
  }

  function renderPlan() {
    planDirty = false;
    const list = $("plan");
    if (!plan) {
      $("plan-info").textContent = "no plan yet";
      list.replaceChildren();
      return;
    }
    const p = plan.probability !== undefined ? `, success probability ${plan.probability}` : "";
    const cost = plan.cost !== undefined ? `, cost ${plan.cost}` : "";
    $("plan-info").textContent = `${plan.why}: ${plan.status}${p}${cost}`;
    list.replaceChildren(...plan.steps.map((step, i) => {
      const classes = [step.startsWith("(assume") ? "assumptive" : "executable"];
      if (plan.done.has(i)) classes.push("done");
      if (plan.current === i) classes.push("current");
      return el("li", { class: classes.join(" "), title: classes[0] === "assumptive" ? "an assumption the plan rests on" : "" }, step);
    }));
  }

  // a task of several: its targets' parts (hidden for a task of one label)
  function renderTargets() {
    targetsDirty = false;
    const card = $("targets-card");
    const parts = targets || (form && form.several ? AVS_TARGETS.open(form.targets, "waiting") : null);
    card.hidden = !parts;
    if (!parts) return;
    $("targets-form").textContent = form ? `${form.name}: ${AVS_TARGETS.formText(form)}` : "";
    $("targets").replaceChildren(AVS_TARGETS.table(parts, form));
  }

  // what came from the building's memory (and the learned priors): hidden for a task in no
  // building
  function renderMemory() {
    memoryDirty = false;
    const card = $("memory-card");
    card.hidden = !building && !memoryEvents.length && !memoryPart && !experiencePart;
    if (card.hidden) return;
    const link = $("memory-building");
    if (building) {
      link.href = `/buildings/${encodeURIComponent(building)}`;
      link.textContent = `building ${building}`;
    }
    const recalled = memoryEvents.find((e) => e.recalled);
    if (memoryPart) AVS_MEMORY.rows($("memory"), AVS_MEMORY.summaryRows(memoryPart));
    else if (recalled) AVS_MEMORY.rows($("memory"), [["tasks before", recalled.tasks], ["places", recalled.places],
      ["rooms", recalled.rooms], ["furniture", recalled.furniture], ["sightings", (recalled.sightings || []).length]]);
    else AVS_MEMORY.rows($("memory"), [["memory", AVS.TERMINAL.has(state) ? "none kept" : "nothing recalled yet"]]);
    $("memory-events").replaceChildren(...memoryEvents.filter((e) => !e.recalled).map((e) =>
      el("li", { class: e.dropped ? "dropped" : e.seen ? "seen" : "", text: AVS_MEMORY.describe(e) })));
    $("experience-part").hidden = !experiencePart;
    if (experiencePart) AVS_MEMORY.rows($("experience"), AVS_MEMORY.experienceRows(experiencePart));
  }

  function renderState() {
    const badge = $("state");
    badge.dataset.state = state;
    badge.className = `state state-${state}`;
    badge.textContent = state + (outcome ? ` (${outcome.outcome})` : "");
    $("outcome").textContent = outcome ? outcome.reason : "";
    $("cancel").hidden = AVS.TERMINAL.has(state) || !state;
    $("clock").textContent = `t = ${M.t.toFixed(1)} s simulated`;
  }

  function renderValue(value, depth = 0) {
    if (value === null || value === undefined) return el("span", { class: "muted", text: "none" });
    if (typeof value !== "object") {
      const text = String(value);
      return el(text.includes("\n") ? "pre" : "span", { text });
    }
    if (depth > 6) return el("code", { text: JSON.stringify(value) });
    if (Array.isArray(value)) {
      if (value.every((v) => v === null || typeof v !== "object")) return el("span", { text: value.join(", ") });
      return el("ol", {}, ...value.map((v) => el("li", {}, renderValue(v, depth + 1))));
    }
    return el("dl", { class: "kv" }, ...Object.entries(value).flatMap(([k, v]) =>
      [el("dt", { text: k }), el("dd", {}, renderValue(v, depth + 1))]));
  }

  async function loadExplanation() {
    const box = $("explanation");
    box.dataset.status = "loading";
    box.textContent = "loading...";
    let answer;
    try {
      const response = await AVS.api(`${base}/explanation`);
      const text = await response.text();
      let body = text;
      try {
        body = JSON.parse(text);
      } catch (_) {
        body = text; // a plain-text explanation is shown as it is
      }
      answer = { status: response.status, ok: response.ok, body };
    } catch (error) {
      box.dataset.status = "error";
      box.textContent = `cannot load the explanation: ${error}`;
      return;
    }
    if (answer.status === 404) {
      box.dataset.status = "none";
      box.className = "explanation muted";
      box.textContent = "no explanation available" +
        (AVS.TERMINAL.has(state) ? "" : " yet (the task has not finished)");
      return;
    }
    if (!answer.ok) {
      box.dataset.status = "error";
      box.textContent = `cannot load the explanation: ${AVS.detailText(answer.body, answer.status)}`;
      return;
    }
    box.dataset.status = "loaded";
    box.className = "explanation";
    const body = answer.body;
    if (typeof body === "string") box.replaceChildren(el("pre", { text: body }));
    else if (body && typeof body.text === "string") box.replaceChildren(el("pre", { text: body.text }));
    else box.replaceChildren(renderValue(body));
  }

  async function onTerminal() {
    const answer = await json(base);
    if (answer.ok) {
      const task = answer.body;
      const dl = $("summary");
      const rows = [["state", task.state]];
      if (task.error) rows.push(["error", task.error]);
      const s = task.summary || {};
      // a task of several shows its targets' parts in their own card, not its first object
      const several = Array.isArray(task.targets);
      for (const key of ["target", "outcome", "reason", "object", "correct", "sim_time_s", "distance_m", "plans",
        "replans", "dt_calls", "views_processed", "wall_time_s"]) {
        if (key in s && !(several && key === "object")) rows.push([key, s[key]]);
      }
      dl.replaceChildren(...rows.flatMap(([k, v]) => [el("dt", { text: k }),
        el("dd", {}, renderValue(v))]));
      if (several) {
        targets = task.targets; // the summary's parts: scored, with positions and times
      } else if (form && form.several) { // ended without a summary's parts (cancelled, failed)
        targets = targets || AVS_TARGETS.open(form.targets);
        for (const part of targets) if (part.outcome === "open") part.outcome = "stopped";
      }
      renderTargets();
      memoryPart = s.memory && typeof s.memory === "object" ? s.memory : null;
      experiencePart = s.experience && typeof s.experience === "object" ? s.experience : null;
      renderMemory();
    }
    const files = [];
    if (["succeeded", "gave_up", "timeout"].includes(state)) {
      files.push(el("li", {}, AVS.fileLink(`${base}/trajectory.png`, { target: "_blank", text: "trajectory.png" })));
    }
    const recording = await AVS.api(`${base}/recording.rrd`, { method: "HEAD" });
    if (recording.ok) {
      files.push(el("li", {}, AVS.fileLink(`${base}/recording.rrd`, { id: "recording-link", text: "Rerun recording (recording.rrd)" }, `${taskId}.rrd`),
        " open it with the Rerun viewer"));
    }
    $("files").replaceChildren(...files);
    if ($("explanation-section").open) loadExplanation();
  }

  // ---- the map --------------------------------------------------------------------------

  function decodeGrid() {
    gridDirty = false;
    const grid = M.grid;
    if (!grid) return;
    decoding += 1;
    const image = new Image();
    image.onload = () => {
      decoding -= 1;
      if (grid !== M.grid) return; // a newer grid is on its way
      const c = document.createElement("canvas");
      c.width = image.width;
      c.height = image.height;
      const ctx = c.getContext("2d", { willReadFrequently: true });
      ctx.drawImage(image, 0, 0);
      const rgba = ctx.getImageData(0, 0, c.width, c.height).data;
      const grey = new Uint8Array(c.width * c.height);
      let lo = [Infinity, Infinity];
      let hi = [-Infinity, -Infinity];
      for (let row = 0; row < c.height; row += 1) {
        for (let col = 0; col < c.width; col += 1) {
          const v = rgba[(row * c.width + col) * 4];
          grey[row * c.width + col] = v;
          if (v < 64 || v > 192) {
            lo = [Math.min(lo[0], col), Math.min(lo[1], row)];
            hi = [Math.max(hi[0], col), Math.max(hi[1], row)];
          }
        }
      }
      M.image = { grid, w: c.width, h: c.height, grey };
      if (lo[0] <= hi[0]) {
        const r = grid.resolution;
        M.known = [grid.origin[0] + lo[0] * r, grid.origin[1] + (c.height - 1 - hi[1]) * r,
          grid.origin[0] + (hi[0] + 1) * r, grid.origin[1] + (c.height - lo[1]) * r];
      }
      tintDirty = true;
      scheduleDraw();
    };
    image.onerror = () => {
      decoding -= 1;
      scheduleDraw();
    };
    image.src = `data:image/png;base64,${grid.png}`;
  }

  // the grid coloured: occupied dark, free white tinted by the believed category of the
  // room of the nearest place (stronger when more certain), unknown left transparent
  function tint() {
    tintDirty = false;
    const img = M.image;
    if (!img) return;
    const { grid, w, h, grey } = img;
    const r = grid.resolution;
    const places = M.places.filter((p) => p[3]).map((p) => {
      const belief = M.rooms[p[3]] || {};
      const [category, prob] = Object.entries(belief)[0] || [null, 0];
      return [p[1], p[2], category ? rgb(colour(category)) : null, prob];
    });
    const canvas = M.tinted && M.tinted.width === w && M.tinted.height === h
      ? M.tinted : Object.assign(document.createElement("canvas"), { width: w, height: h });
    const ctx = canvas.getContext("2d");
    const out = ctx.createImageData(w, h);
    const data = out.data;
    const reach2 = 2.5 * 2.5;
    for (let row = 0; row < h; row += 1) {
      const y = grid.origin[1] + (h - row - 0.5) * r;
      for (let col = 0; col < w; col += 1) {
        const i = row * w + col;
        const v = grey[i];
        const o = i * 4;
        if (v < 64) {
          data[o] = data[o + 1] = data[o + 2] = 35;
          data[o + 3] = 255;
        } else if (v > 192) {
          const x = grid.origin[0] + (col + 0.5) * r;
          let best = null;
          let bestD = reach2;
          for (const p of places) {
            const d = (p[0] - x) ** 2 + (p[1] - y) ** 2;
            if (d < bestD) {
              bestD = d;
              best = p;
            }
          }
          let c = [255, 255, 255];
          if (best && best[2]) {
            const a = 0.12 + 0.3 * best[3];
            c = best[2].map((k) => Math.round(255 * (1 - a) + k * a));
          }
          data[o] = c[0];
          data[o + 1] = c[1];
          data[o + 2] = c[2];
          data[o + 3] = 255;
        }
      }
    }
    ctx.putImageData(out, 0, 0);
    M.tinted = canvas;
  }

  function scheduleDraw() {
    if (drawPending) return;
    drawPending = true;
    requestAnimationFrame(draw);
  }

  function bounds() {
    let b = M.known ? [...M.known] : null;
    const add = (x, y) => {
      if (!b) b = [x, y, x, y];
      else b = [Math.min(b[0], x), Math.min(b[1], y), Math.max(b[2], x), Math.max(b[3], y)];
    };
    for (const p of M.path) add(p[0], p[1]);
    if (M.pose) add(M.pose[0], M.pose[1]);
    for (const p of M.placeholders) add(p[1], p[2]);
    if (!b) return null;
    const m = 0.6;
    return [b[0] - m, b[1] - m, b[2] + m, b[3] + m];
  }

  function draw() {
    drawPending = false;
    if (tintDirty) tint();
    const canvas = $("map");
    const dpr = window.devicePixelRatio || 1;
    const width = Math.max(200, canvas.clientWidth);
    const b = bounds();
    const aspect = b ? Math.min(1.2, Math.max(0.45, (b[3] - b[1]) / (b[2] - b[0]))) : 0.7;
    const height = Math.round(width * aspect);
    if (canvas.width !== Math.round(width * dpr) || canvas.height !== Math.round(height * dpr)) {
      canvas.width = Math.round(width * dpr);
      canvas.height = Math.round(height * dpr);
      canvas.style.height = `${height}px`;
    }
    const ctx = canvas.getContext("2d");
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    ctx.fillStyle = "#dcdcdc";
    ctx.fillRect(0, 0, width, height);
    if (!b) {
      ctx.fillStyle = "#555";
      ctx.font = "14px sans-serif";
      ctx.fillText("waiting for the robot's first map...", 16, 28);
      stamp();
      return;
    }
    const scale = Math.min(width / (b[2] - b[0]), height / (b[3] - b[1]));
    const ox = (width - (b[2] - b[0]) * scale) / 2;
    const oy = (height - (b[3] - b[1]) * scale) / 2;
    const X = (x) => ox + (x - b[0]) * scale;
    const Y = (y) => oy + (b[3] - y) * scale;

    if (M.tinted && M.image) {
      const g = M.image.grid;
      ctx.imageSmoothingEnabled = false;
      ctx.drawImage(M.tinted, X(g.origin[0]), Y(g.origin[1] + M.image.h * g.resolution),
        M.image.w * g.resolution * scale, M.image.h * g.resolution * scale);
    }
    // view cones: the latest set strongest, coloured by the search's result
    M.cones.forEach((set, k) => {
      const latest = k === M.cones.length - 1;
      const top = Math.max(1e-9, ...set.cones.map((c) => c[3]));
      const hue = set.result === "confirmed" ? "46,160,67" : set.result === "rejected" ? "120,120,120" : "255,140,0";
      for (const [x, y, yaw, p] of set.cones) {
        ctx.beginPath();
        ctx.moveTo(X(x), Y(y));
        ctx.arc(X(x), Y(y), set.range * scale, -(yaw + set.fov / 2), -(yaw - set.fov / 2));
        ctx.closePath();
        ctx.fillStyle = `rgba(${hue},${(latest ? 0.1 : 0.04) + (latest ? 0.35 : 0.1) * (p / top)})`;
        ctx.fill();
        if (latest) {
          ctx.strokeStyle = `rgba(${hue},0.8)`;
          ctx.lineWidth = 1;
          ctx.stroke();
        }
      }
    });
    // keep-out discs where the base was blocked
    ctx.strokeStyle = "#c00";
    ctx.lineWidth = 1.5;
    for (const [x, y, r] of M.blocked) {
      ctx.beginPath();
      ctx.arc(X(x), Y(y), r * scale, 0, 2 * Math.PI);
      ctx.stroke();
    }
    // doors
    ctx.strokeStyle = "#e0f";
    ctx.lineWidth = 4;
    for (const [, x0, y0, x1, y1] of M.doors) {
      ctx.beginPath();
      ctx.moveTo(X(x0), Y(y0));
      ctx.lineTo(X(x1), Y(y1));
      ctx.stroke();
    }
    // the robot's path
    if (M.path.length) {
      ctx.strokeStyle = "#0b3d91";
      ctx.lineWidth = 2;
      ctx.beginPath();
      M.path.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
      ctx.stroke();
      ctx.fillStyle = "#2a2";
      ctx.beginPath();
      ctx.arc(X(M.path[0][0]), Y(M.path[0][1]), 5, 0, 2 * Math.PI);
      ctx.fill();
    }
    // places (coloured by their room's likeliest category) and placeholders (hollow)
    for (const [, x, y, room] of M.places) {
      const belief = room ? M.rooms[room] || {} : {};
      const category = Object.keys(belief)[0];
      ctx.fillStyle = colour(category);
      ctx.beginPath();
      ctx.arc(X(x), Y(y), 4, 0, 2 * Math.PI);
      ctx.fill();
    }
    ctx.strokeStyle = "#444";
    ctx.lineWidth = 1.2;
    for (const [, x, y] of M.placeholders) {
      ctx.beginPath();
      ctx.arc(X(x), Y(y), 4, 0, 2 * Math.PI);
      ctx.stroke();
    }
    // room labels at the centre of their places: the believed category and its probability
    ctx.font = "12px sans-serif";
    for (const [room, belief] of Object.entries(M.rooms)) {
      const mine = M.places.filter((p) => p[3] === room);
      if (!mine.length) continue;
      const cx = mine.reduce((s, p) => s + p[1], 0) / mine.length;
      const cy = mine.reduce((s, p) => s + p[2], 0) / mine.length;
      const [category, p] = Object.entries(belief)[0] || ["?", 0];
      const text = `${room}: ${category} ${Number(p).toFixed(2)}`;
      const w = ctx.measureText(text).width;
      ctx.fillStyle = "rgba(255,255,255,0.8)";
      ctx.fillRect(X(cx) - w / 2 - 3, Y(cy) - 22, w + 6, 16);
      ctx.fillStyle = colour(category);
      ctx.fillText(text, X(cx) - w / 2, Y(cy) - 10);
    }
    // detections: stars for those in a searched location, crosses for the rest
    for (const [x, y, , matched] of M.detections) marker(ctx, X(x), Y(y), matched ? "#f90" : "#888", matched);
    for (const [x, y, , detected] of M.observations) marker(ctx, X(x), Y(y), detected ? "#f60" : "#aaa", detected);
    // known objects
    ctx.font = "bold 12px sans-serif";
    for (const [id, label, x, y] of M.objects) {
      ctx.fillStyle = "#000";
      ctx.beginPath();
      ctx.arc(X(x), Y(y), 3.5, 0, 2 * Math.PI);
      ctx.fill();
      ctx.fillText(`${id}: ${label}`, X(x) + 6, Y(y) - 6);
    }
    // the robot
    if (M.pose) {
      const [x, y, yaw] = M.pose;
      ctx.save();
      ctx.translate(X(x), Y(y));
      ctx.rotate(-yaw);
      ctx.fillStyle = "#d00";
      ctx.beginPath();
      ctx.moveTo(11, 0);
      ctx.lineTo(-7, 7);
      ctx.lineTo(-7, -7);
      ctx.closePath();
      ctx.fill();
      ctx.restore();
    }
    // a 1 m scale bar
    ctx.strokeStyle = "#000";
    ctx.lineWidth = 2;
    ctx.beginPath();
    ctx.moveTo(12, height - 12);
    ctx.lineTo(12 + scale, height - 12);
    ctx.stroke();
    ctx.fillStyle = "#000";
    ctx.font = "11px sans-serif";
    ctx.fillText("1 m", 14, height - 16);
    renderLegend();
    stamp();
  }

  function marker(ctx, x, y, fill, strong) {
    ctx.fillStyle = fill;
    ctx.strokeStyle = fill;
    ctx.lineWidth = 2;
    if (strong) {
      ctx.beginPath();
      for (let k = 0; k < 10; k += 1) {
        const r = k % 2 ? 3 : 8;
        const a = -Math.PI / 2 + (k * Math.PI) / 5;
        ctx.lineTo(x + r * Math.cos(a), y + r * Math.sin(a));
      }
      ctx.closePath();
      ctx.fill();
    } else {
      ctx.beginPath();
      ctx.moveTo(x - 4, y - 4);
      ctx.lineTo(x + 4, y + 4);
      ctx.moveTo(x + 4, y - 4);
      ctx.lineTo(x - 4, y + 4);
      ctx.stroke();
    }
  }

  let legendKey = "";
  function renderLegend() {
    const categories = [...new Set(Object.values(M.rooms).map((b) => Object.keys(b)[0]).filter(Boolean))].sort();
    const key = categories.join(",");
    if (key === legendKey) return;
    legendKey = key;
    const swatch = (c, text) => {
      const box = el("i");
      box.style.background = c; // CSSOM, allowed by the page's content security policy
      return el("span", { class: "swatch" }, box, text);
    };
    $("legend").replaceChildren(...categories.map((c) => swatch(colour(c), c)),
      el("span", { class: "muted", text: "filled dots: places; hollow: placeholders; magenta: doors; wedges: view cones; stars: detections; red triangle: robot" }));
  }

  // every event shown since the last frame is stamped once the frame is drawn (and the
  // grid it brought decoded)
  function stamp() {
    if (decoding > 0 || gridDirty) return;
    const now = Date.now();
    for (const seq of unstamped) page.shown[seq] = now;
    unstamped = [];
    if (page.stream === "ended" && page.complete === null) page.complete = performance.now();
  }

  // ---- following the task ---------------------------------------------------------------

  function onBatch(batch) {
    let terminal = false;
    for (const e of batch) {
      apply(e);
      if (e.type === "state" && AVS.TERMINAL.has(e.state)) terminal = true;
    }
    page.events += batch.length;
    page.batches += 1;
    for (const e of batch) {
      const sent = typeof e.sent === "number" ? e.sent : e.type === "state" ? e.time : undefined;
      if (typeof sent === "number") page.sent[e.seq] = sent * 1000;
    }
    renderLog(batch);
    if (planDirty) renderPlan();
    if (targetsDirty) renderTargets();
    if (memoryDirty) renderMemory();
    renderState();
    for (const e of batch) unstamped.push(e.seq);
    if (gridDirty) decodeGrid();
    scheduleDraw();
    if (terminal) onTerminal();
  }

  async function cancel() {
    const answer = await json(base, { method: "DELETE" });
    const message = $("task-message");
    if (answer.status === 401) {
      AVS.askForKey("enter the service's API key to cancel");
      message.textContent = "this service needs an API key to cancel a task";
    } else if (!answer.ok) {
      message.textContent = AVS.detailText(answer.body, answer.status);
    } else {
      message.textContent = "cancel requested";
    }
  }

  document.addEventListener("DOMContentLoaded", async () => {
    let needsKey = false;
    AVS.setupKey(() => {
      if (needsKey) window.location.reload(); // the key given: read the task again
    });
    $("task-id").textContent = taskId;
    document.title = `avs-planner: task ${AVS.shortId(taskId)}`;
    $("cancel").addEventListener("click", cancel);
    $("explanation-section").addEventListener("toggle", () => {
      if ($("explanation-section").open) loadExplanation();
    });
    window.addEventListener("resize", scheduleDraw);
    const answer = await json(base);
    if (answer.status === 401) {
      needsKey = true;
      AVS.askForKey("enter the service's API key to see this task");
    }
    if (!answer.ok) {
      state = "unknown";
      renderState();
      $("state").textContent = answer.status === 404 ? "no such task" : `error ${answer.status}`;
      $("task-message").textContent = AVS.detailText(answer.body, answer.status);
      page.stream = "gone";
      return;
    }
    const r = answer.body.request;
    $("request").replaceChildren(...Object.entries(r).filter(([, v]) => v !== null && v !== "" &&
      !(typeof v === "object" && !Array.isArray(v) && !Object.keys(v).length)).flatMap(([k, v]) =>
      [el("dt", { text: k }), el("dd", { text: Array.isArray(v) ? v.join(", ") : typeof v === "object" ? JSON.stringify(v) : String(v) })]));
    state = answer.body.state;
    form = answer.body.task || null;
    building = typeof r.building === "string" ? r.building : null;
    renderTargets();
    renderMemory();
    renderState();
    scheduleDraw();
    page.stream = "live";
    $("stream").textContent = "following events live";
    const follow = AVS.followEvents(taskId, onBatch, {
      onError: () => {
        page.stream = "reconnecting";
        $("stream").textContent = "connection lost, reconnecting...";
      },
    });
    const how = await follow.finished;
    page.stream = how === "ended" ? "ended" : how;
    $("stream").textContent = how === "ended" ? "the task has ended: all events shown" : `stream ${how}`;
    scheduleDraw();
  });
})();
