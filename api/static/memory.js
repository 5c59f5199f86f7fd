// What a task in a building took from memory (docs/memory.md), on the task page: the trace's
// `memory` events (what was recalled, each sighting checked or dropped) while it runs, then
// the summary's `memory` and `experience` parts. Shared with the buildings page. Needs AVS
// (common.js).
"use strict";

const AVS_MEMORY = (() => {
  const { el } = AVS;
  const n = (v, d = 2) => (typeof v === "number" ? Number(v.toFixed(d)) : v);
  const at = (p) => (Array.isArray(p) ? `(${p.slice(0, 3).map((v) => n(v)).join(", ")})` : "");

  // one `memory` event in a line
  function describe(e) {
    if (e.recalled) {
      const sightings = (e.sightings || []).length;
      return `recalled ${e.tasks} task(s) before: ${e.places} places, ${e.rooms} rooms, ` +
        `${e.furniture} furniture, ${sightings} sighting(s)${e.faded ? `, ${e.faded} faded` : ""}`;
    }
    if (e.checked) {
      return `checked ${e.checked} at ${at(e.position)} (P in place ${n(e.weight, 3)}): ` +
        (e.seen ? `seen again${e.object ? ` as ${e.object}` : ""}` : "not there, dropped");
    }
    if (e.unreachable) return `${e.unreachable} at ${at(e.position)}: no way to look, kept for later`;
    const { t, wall, type, seq, retry, ...rest } = e;
    return JSON.stringify(rest);
  }

  function rows(dl, pairs) {
    dl.replaceChildren(...pairs.filter(([, v]) => v !== undefined && v !== null).flatMap(([k, v]) =>
      [el("dt", { text: k }), el("dd", { text: typeof v === "object" ? JSON.stringify(v) : String(v) })]));
  }

  // the summary's `memory` part as rows
  function summaryRows(part) {
    return [["tasks before", part.tasks_before], ["building clock", part.building_clock_s !== undefined ? `${part.building_clock_s} s` : undefined],
      ["furniture", part.furniture], ["sightings", part.sightings], ["checked", part.checked],
      ["confirmed", part.confirmed], ["saved", part.saved]];
  }

  // the summary's `experience` part as rows
  function experienceRows(part) {
    return [["store", part.store], ["building", part.building], ["updated", part.updated],
      ...Object.entries(part).filter(([k]) => !["store", "building", "updated"].includes(k))];
  }

  return { describe, rows, summaryRows, experienceRows, at, n };
})();
