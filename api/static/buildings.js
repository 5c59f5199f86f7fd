// The buildings page: every building the service remembers (/buildings), and one in full
// (/buildings/ID) with a Forget button (DELETE /v1/buildings/ID).
"use strict";

(() => {
  const { el, json } = AVS;
  const $ = (id) => document.getElementById(id);
  const parts = window.location.pathname.split("/").filter(Boolean);
  const buildingId = parts.length > 1 ? decodeURIComponent(parts[1]) : null;
  const base = buildingId ? `/v1/buildings/${encodeURIComponent(buildingId)}` : "/v1/buildings";
  let needsKey = false;

  function worldText(world) {
    if (!world) return "";
    if (world.world) return world.world;
    if (world.generate) return `generated ${world.generate.style || "office"} ${world.generate.seed}`;
    return "inline world file";
  }

  function age(seconds) {
    if (typeof seconds !== "number") return "";
    if (seconds < 120) return `${seconds.toFixed(0)} s`;
    if (seconds < 7200) return `${(seconds / 60).toFixed(0)} min`;
    if (seconds < 172800) return `${(seconds / 3600).toFixed(1)} h`;
    return `${(seconds / 86400).toFixed(1)} days`;
  }

  function refused(answer, what) {
    if (answer.status === 401) {
      needsKey = true;
      AVS.askForKey(`enter the service's API key to ${what}`);
      return `this service needs an API key to ${what}: enter it above`;
    }
    return AVS.detailText(answer.body, answer.status);
  }

  async function showList() {
    $("list-card").hidden = false;
    const answer = await json(base);
    if (!answer.ok) {
      $("building-count").textContent = refused(answer, "see its buildings");
      return;
    }
    const rows = answer.body.data.map((b) => {
      const m = b.memory || {};
      const link = el("a", { href: `/buildings/${encodeURIComponent(b.id)}`, text: b.id });
      const last = b.last_task ? el("a", { href: `/tasks/${encodeURIComponent(b.last_task)}`, text: AVS.shortId(b.last_task) }) : "";
      return el("tr", { "data-id": b.id },
        el("td", {}, link, b.busy ? el("span", { class: "state state-running", text: "busy" }) : null),
        el("td", { text: worldText(b.world) }),
        el("td", { text: b.tasks }),
        el("td", {}, last, " ", el("span", { class: "muted", text: AVS.when(b.last_task_at) })),
        el("td", { text: m.places ?? "" }), el("td", { text: m.rooms ?? "" }),
        el("td", { text: m.objects ?? "" }), el("td", { text: m.sightings ?? "" }),
        el("td", { text: b.learned_priors ? "yes" : "no" }),
        el("td", { class: "muted", text: m.error ? m.error : "" }));
    });
    $("buildings").tBodies[0].replaceChildren(...rows);
    $("building-count").textContent = `${answer.body.count} building${answer.body.count === 1 ? "" : "s"}`;
  }

  async function showBuilding() {
    $("detail-card").hidden = false;
    $("building-id").textContent = buildingId;
    $("building-crumb").textContent = buildingId;
    document.title = `avs-planner: building ${buildingId}`;
    const answer = await json(base);
    if (!answer.ok) {
      $("building-state").textContent = answer.status === 404 ? "no such building" : `error ${answer.status}`;
      $("building-message").textContent = refused(answer, "see this building");
      $("forget").hidden = true;
      return;
    }
    const b = answer.body;
    const m = b.memory || {};
    $("building-state").textContent = b.busy ? "a task is queued or running here" : "";
    const labels = m.labels ? Object.entries(m.labels).map(([k, v]) => `${k} ${v}`).join(", ") : undefined;
    AVS_MEMORY.rows($("building-summary"), [
      ["world", worldText(b.world)], ["tasks", b.tasks], ["first task", AVS.when(b.created_at)],
      ["memory", b.memory ? undefined : "nothing kept yet"], ["error", m.error],
      ["tasks remembered", m.tasks], ["building clock", m.clock_s !== undefined ? `${m.clock_s} s` : undefined],
      ["saved", m.saved], ["places", m.places], ["rooms", m.rooms], ["doors", m.doors],
      ["objects", m.objects], ["sightings", m.sightings], ["labels", labels],
      ["learned priors", b.learned_priors ? "yes" : "no"]]);
    $("objects").tBodies[0].replaceChildren(...b.objects.map((o) => el("tr", { class: `kind-${o.kind}` },
      el("td", { text: o.kind }), el("td", { text: o.label }), el("td", { text: o.support || "" }),
      el("td", { text: AVS_MEMORY.at(o.position) }), el("td", { text: o.seen_at }),
      el("td", { text: age(o.age_s) }), el("td", { text: o.p_in_place }))));
    const experience = $("experience");
    if (b.experience) {
      const e = b.experience;
      const rates = (e.rates || []).filter((r) => r.found || r.exposure);
      experience.className = "";
      experience.replaceChildren(
        el("p", { class: "muted", text: `episodes: ${Object.entries(e.episodes || {}).map(([k, v]) => `${k} ${v}`).join(", ")}` +
          (e.error ? `; ${e.error}` : "") }),
        el("table", { class: "tasks" },
          el("thead", {}, el("tr", {}, ...["label", "where", "file", "learned", "found", "exposure"].map((h) => el("th", { text: h })))),
          el("tbody", {}, ...rates.map((r) => el("tr", {},
            el("td", { text: r.label }),
            el("td", { text: r.support ? `${r.relation} ${r.support} in ${r.category}` : `in ${r.category}` }),
            el("td", { text: r.file }), el("td", { text: r.learned }),
            el("td", { text: r.found }), el("td", { text: r.exposure }))))));
    }
    $("history").tBodies[0].replaceChildren(...b.history.map((t) => el("tr", {},
      el("td", {}, el("a", { href: `/tasks/${encodeURIComponent(t.id)}`, text: AVS.shortId(t.id) })),
      el("td", { text: t.name || "" }),
      el("td", {}, el("span", { class: `state state-${t.state}`, text: t.state })),
      el("td", { text: t.tasks_before ?? "" }),
      el("td", { text: AVS.when(t.created_at) }), el("td", { text: AVS.when(t.finished_at) }))));
  }

  async function forget() {
    const message = $("building-message");
    if (!window.confirm(`Forget building ${buildingId}? Its map, remembered objects and learned priors are deleted; its tasks stay.`)) return;
    const answer = await json(base, { method: "DELETE" });
    if (answer.status === 204) {
      message.className = "message";
      message.textContent = "forgotten";
      window.location.assign("/buildings");
      return;
    }
    message.className = "message error";
    message.textContent = refused(answer, "forget a building");
  }

  document.addEventListener("DOMContentLoaded", async () => {
    AVS.setupKey(() => {
      if (needsKey) window.location.reload();
    });
    if (buildingId) {
      $("forget").addEventListener("click", forget);
      await showBuilding();
    } else {
      await showList();
    }
  });
})();
