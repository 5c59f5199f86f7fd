// The task list and the submit form.
"use strict";

(() => {
  const { el, json } = AVS;
  const $ = (id) => document.getElementById(id);
  let worlds = [];

  async function loadChoices() {
    const [w, s] = await Promise.all([json("/v1/worlds"), json("/v1/strategies")]);
    worlds = w.ok ? w.body.data : [];
    const worldSelect = $("f-world");
    worldSelect.replaceChildren(...worlds.map((world) => el("option", { value: world.name, text: world.name })));
    if (worlds.some((world) => world.name === "office")) worldSelect.value = "office";
    const strategies = s.ok ? s.body.data : [{ name: "switching", summary: "" }];
    $("f-strategy").replaceChildren(...strategies.map((st) =>
      el("option", { value: st.name, text: st.name, title: st.summary })));
    $("f-strategy").value = "switching";
    fillRooms();
  }

  function fillRooms() {
    const world = worlds.find((w) => w.name === $("f-world").value);
    const rooms = world ? world.rooms : [];
    $("f-start-room").replaceChildren(el("option", { value: "", text: "world's default" }),
      ...rooms.map((room) => el("option", { value: room, text: room })));
  }

  function body() {
    const out = { world: $("f-world").value };
    // one label is a `target`; several (separated by commas) are `targets`, with the mode
    const labels = $("f-target").value.split(/[\s,]+/).filter(Boolean);
    if (labels.length > 1) {
      out.targets = labels;
      out.mode = $("f-mode").value;
    } else {
      out.target = labels[0] || "";
    }
    if ($("f-count").value === "all") out.count = "all";
    const stop = $("f-stop").value.trim();
    if (stop !== "") out.stop_below = Number(stop);
    const category = $("f-category").value.trim();
    if (category) out.category = category;
    if ($("f-robot").value) out.robot = $("f-robot").value;
    if ($("f-start-room").value) out.start_room = $("f-start-room").value;
    const pose = ["f-x", "f-y", "f-yaw"].map((id) => $(id).value.trim());
    if (pose.some((v) => v !== "")) out.start = pose.map((v) => (v === "" ? null : Number(v)));
    const seed = $("f-seed").value.trim();
    if (seed !== "") out.seed = Number(seed);
    if ($("f-strategy").value) out.strategy = $("f-strategy").value;
    const budget = $("f-budget").value.trim();
    if (budget !== "") out.time_budget_s = Number(budget);
    const building = $("f-building").value.trim();
    if (building) out.building = building;
    const since = $("f-since").value.trim();
    if (since !== "") out.since_s = Number(since);
    return out;
  }

  const FIELDS = {
    world: "f-world", target: "f-target", targets: "f-target", mode: "f-mode", count: "f-count",
    stop_below: "f-stop", category: "f-category", robot: "f-robot",
    start_room: "f-start-room", start: "f-x", seed: "f-seed", strategy: "f-strategy",
    time_budget_s: "f-budget", building: "f-building", since_s: "f-since",
  };

  function showErrors(detail) {
    const message = $("form-message");
    document.querySelectorAll(".field-error").forEach((n) => n.remove());
    document.querySelectorAll(".invalid").forEach((n) => n.classList.remove("invalid"));
    const items = [];
    for (const d of Array.isArray(detail) ? detail : [{ msg: String(detail) }]) {
      const field = d.loc ? d.loc[1] : null;
      const input = field ? $(FIELDS[field]) : null;
      if (input) {
        input.classList.add("invalid");
        const holder = input.closest("label, fieldset") || input.parentElement;
        holder.append(el("span", { class: "field-error", text: d.msg }));
      }
      items.push(el("li", { text: (field ? `${field}: ` : "") + d.msg }));
    }
    message.className = "message error";
    message.replaceChildren(el("ul", {}, ...items));
  }

  async function submit(event) {
    event.preventDefault();
    const button = $("submit-button");
    const message = $("form-message");
    button.disabled = true;
    message.className = "message";
    message.textContent = "submitting...";
    try {
      const answer = await json("/v1/tasks", {
        method: "POST",
        headers: { "Content-Type": "application/json" },
        body: JSON.stringify(body()),
      });
      if (answer.status === 202) {
        message.textContent = `task ${answer.body.id} queued`;
        window.location.assign(`/tasks/${encodeURIComponent(answer.body.id)}`);
        return;
      }
      if (answer.status === 401) {
        showErrors("this service needs an API key: enter it above (X-API-Key) and submit again");
        AVS.askForKey("enter the service's API key");
      } else if (answer.status === 422 && answer.body) {
        showErrors(answer.body.detail);
      } else {
        showErrors(AVS.detailText(answer.body, answer.status));
      }
    } catch (error) {
      showErrors(`the service did not answer: ${error}`);
    } finally {
      button.disabled = false;
    }
  }

  async function refresh() {
    const state = $("state-filter").value;
    const query = state ? `?state=${encodeURIComponent(state)}&limit=100` : "?limit=100";
    const answer = await json(`/v1/tasks${query}`);
    if (answer.status === 401) {
      $("task-count").textContent = "this service needs an API key to list tasks: enter it above";
      AVS.askForKey("enter the service's API key to see tasks");
      return;
    }
    if (!answer.ok) {
      $("task-count").textContent = `cannot list tasks: ${AVS.detailText(answer.body, answer.status)}`;
      return;
    }
    const rows = answer.body.data.map((task) => {
      const r = task.request;
      const link = el("a", { href: `/tasks/${encodeURIComponent(task.id)}`, text: AVS.shortId(task.id) });
      return el("tr", { "data-id": task.id },
        el("td", {}, link),
        el("td", { text: (task.task ? task.task.name : r.target || "") + (r.category ? ` (${r.category})` : "") }),
        el("td", { text: r.world || (r.generate ? `generated ${r.generate.style || "office"} ${r.generate.seed}` : "(inline)") }),
        el("td", { text: r.strategy || "switching" }),
        el("td", { text: r.seed ?? "" }),
        el("td", {}, el("span", { class: `state state-${task.state}`, text: task.state })),
        el("td", { text: task.events }),
        el("td", { text: AVS.when(task.created_at) }));
    });
    $("tasks").tBodies[0].replaceChildren(...rows);
    $("task-count").textContent = `${answer.body.count} task${answer.body.count === 1 ? "" : "s"}`;
  }

  document.addEventListener("DOMContentLoaded", async () => {
    AVS.setupKey(refresh);
    $("f-world").addEventListener("change", fillRooms);
    $("submit-form").addEventListener("submit", submit);
    $("state-filter").addEventListener("change", refresh);
    await loadChoices();
    await refresh();
    setInterval(() => {
      if (!document.hidden) refresh();
    }, 2000);
  });
})();
