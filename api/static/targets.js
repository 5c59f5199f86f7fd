// A task of several objects on the task page: each target label's part (its outcome, the
// objects reported for it and when its part ended), from the task's summary once it ended and
// from its `task`, `turn` and `target` events while it runs. Needs AVS (common.js).
"use strict";

const AVS_TARGETS = (() => {
  const OUTCOMES = {
    waiting: ["waiting", "queued"], open: ["searching", "running"], found: ["found", "succeeded"], gave_up: ["gave up", "gave_up"],
    timeout: ["timeout", "timeout"], not_needed: ["not needed", "cancelled"],
    stopped: ["stopped", "failed"], // the task ended without this label's part (cancelled, failed)
  };

  // the parts of a task whose `task` event names `labels`, none ended yet ("waiting": the
  // task has not begun)
  function open(labels, outcome = "open") {
    return labels.map((label) => ({ label, outcome, reason: "", objects: [], sim_time_s: null, turns: 0 }));
  }

  // a `turn` event (its start) or a `target` event (a label's part ended) applied to `parts`;
  // `objects` are the map's known objects ([id, label, x, y, room]), `t0` the task's start
  function apply(parts, e, objects, t0) {
    const part = parts.find((p) => p.label === e.target);
    if (!part) return;
    if (e.type === "turn" && e.status === "start") part.turns += 1;
    if (e.type === "target") {
      part.outcome = e.outcome;
      part.reason = e.reason || "";
      part.objects = (e.found || []).map((id) => {
        const known = objects.find((o) => o[0] === id);
        return known ? { id, label: known[1], position: [known[2], known[3]], room: known[4] } : { id, label: e.target };
      });
      if (typeof e.t === "number") part.sim_time_s = Math.round((e.t - (t0 || 0)) * 100) / 100;
    }
  }

  // "object2 at (1.44, 7.58) in room1", "(not a true cup)" when the scoring says so
  function where(obj) {
    const p = Array.isArray(obj.position) ? obj.position : [];
    const at = p.length >= 2 ? ` at (${p.slice(0, 2).map((v) => Number(v).toFixed(2)).join(", ")})` : "";
    const wrong = obj.correct === false ? ` (not a true ${obj.label})` : "";
    return `${obj.id}${at}${obj.room ? ` in ${obj.room}` : ""}${wrong}`;
  }

  // a table with one row per target: label, outcome (a badge with the reason as its title;
  // a part that did not find says why underneath, and so does a count of every instance),
  // its objects, the simulated time its part ended, its turns
  function table(parts, form) {
    const { el } = AVS;
    const counting = Boolean(form && form.count === "all");
    const rows = parts.map((part) => {
      const [text, state] = OUTCOMES[part.outcome] || [part.outcome, ""];
      const outcome = el("td", {}, el("span", { class: `state state-${state}`, text, title: part.reason || "" }));
      const why = part.outcome === "found" ? counting : part.outcome !== "not_needed";
      if (part.reason && why) outcome.append(el("div", { class: "why muted", text: part.reason }));
      const objects = part.objects && part.objects.length
        ? el("ul", { class: "objects" }, ...part.objects.map((o) => el("li", { text: where(o) })))
        : el("span", { class: "muted", text: "none" });
      const time = typeof part.sim_time_s === "number" ? `${part.sim_time_s.toFixed(1)} s` : "";
      return el("tr", { "data-label": part.label, "data-outcome": part.outcome },
        el("td", {}, el("b", { text: part.label })), outcome, el("td", {}, objects),
        el("td", { class: "num", text: time }), el("td", { class: "num", text: String(part.turns ?? "") }));
    });
    return el("table", { class: "targets" },
      el("thead", {}, el("tr", {}, ...["target", "outcome", "objects", "time", "turns"].map((h) => el("th", { text: h })))),
      el("tbody", {}, ...rows));
  }

  // how the form reads: "all of them", "any one of them", "every instance (until P(another) < 0.1)"
  function formText(form) {
    if (!form) return "";
    if (form.count === "all") return `every instance, until P(another) < ${form.stop_below ?? 0.1}`;
    return form.mode === "any" ? "the first of any of them" : "one of each";
  }

  return { open, apply, table, formText, where };
})();
