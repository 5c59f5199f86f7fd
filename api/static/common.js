// Shared by the pages: API calls with the key in a header, the key form, an SSE reader.
"use strict";

const AVS = (() => {
  const KEY = "avs-api-key";
  const TERMINAL = new Set(["succeeded", "failed", "gave_up", "timeout", "cancelled"]);

  function apiKey() {
    return sessionStorage.getItem(KEY) || "";
  }

  // fetch() on the API with the key (if one was given) in X-API-Key: never in a URL
  function api(path, options = {}) {
    const headers = new Headers(options.headers || {});
    const key = apiKey();
    if (key) headers.set("X-API-Key", key);
    return fetch(path, { ...options, headers });
  }

  async function json(path, options = {}) {
    const response = await api(path, options);
    let body = null;
    try {
      body = await response.json();
    } catch (_) {
      body = null;
    }
    return { status: response.status, ok: response.ok, body, headers: response.headers };
  }

  function el(tag, attrs = {}, ...children) {
    const node = document.createElement(tag);
    for (const [name, value] of Object.entries(attrs)) {
      if (value === null || value === undefined || value === false) continue;
      if (name === "class") node.className = value;
      else if (name === "text") node.textContent = value;
      else if (name.startsWith("data-")) node.setAttribute(name, value);
      else node[name] = value;
    }
    for (const child of children) {
      if (child === null || child === undefined) continue;
      node.append(child instanceof Node ? child : document.createTextNode(String(child)));
    }
    return node;
  }

  function detailText(body, status) {
    if (!body || body.detail === undefined) return `HTTP ${status}`;
    const detail = body.detail;
    if (typeof detail === "string") return detail;
    if (Array.isArray(detail)) {
      return detail.map((d) => (d.loc ? `${d.loc.slice(1).join(".")}: ` : "") + d.msg).join("; ");
    }
    return JSON.stringify(detail);
  }

  // the key form in the header: shown as needed when the service has a key
  async function setupKey(onChange) {
    const form = document.getElementById("key-form");
    const input = document.getElementById("api-key");
    const status = document.getElementById("key-status");
    if (!form) return;
    const show = () => {
      status.textContent = apiKey() ? "key set for this tab" : "no key";
      form.classList.toggle("has-key", Boolean(apiKey()));
    };
    form.addEventListener("submit", (event) => {
      event.preventDefault();
      const value = input.value.trim();
      if (value) sessionStorage.setItem(KEY, value);
      else sessionStorage.removeItem(KEY);
      input.value = "";
      show();
      if (onChange) onChange();
    });
    show();
    const health = await json("/v1/health");
    if (health.ok && health.body && health.body.open_access) {
      form.classList.add("open");
      status.textContent = apiKey() ? "key set (this service needs none)" : "open service: no key needed";
    } else {
      form.classList.add("needs-key");
    }
  }

  // a link to a file of the API: plain when no key is set; with a key, a click fetches it
  // with the key in X-API-Key and opens (or saves) the result, since a link sends no header
  function fileLink(path, attrs, filename) {
    const link = el("a", { ...attrs, href: path });
    link.addEventListener("click", async (event) => {
      if (!apiKey()) return;
      event.preventDefault();
      const response = await api(path);
      if (!response.ok) {
        if (response.status === 401) askForKey("enter the service's API key to open this file");
        return;
      }
      const url = URL.createObjectURL(await response.blob());
      if (filename) {
        const save = el("a", { href: url, download: filename });
        document.body.append(save);
        save.click();
        save.remove();
      } else {
        window.open(url, "_blank", "noopener");
      }
      setTimeout(() => URL.revokeObjectURL(url), 60000);
    });
    return link;
  }

  function askForKey(message) {
    const form = document.getElementById("key-form");
    const status = document.getElementById("key-status");
    if (form) form.classList.add("needs-key", "asking");
    if (status) status.textContent = message;
    const input = document.getElementById("api-key");
    if (input) input.focus();
  }

  // Server-Sent Events read with fetch() (EventSource cannot send headers): calls
  // onBatch(events) with the events of each chunk read (each with its `seq`), resumes with
  // Last-Event-ID after a disconnect or a `shutdown` event, and resolves when the stream
  // ends with the task (or `stop()` is called).
  function followEvents(taskId, onBatch, { onError } = {}) {
    const controller = new AbortController();
    let last = 0;
    let retry = 2000;
    let stopped = false;

    async function once() {
      const headers = { Accept: "text/event-stream" };
      if (last) headers["Last-Event-ID"] = String(last);
      const response = await api(`/v1/tasks/${encodeURIComponent(taskId)}/events`, {
        headers, signal: controller.signal, cache: "no-store",
      });
      if (response.status === 404) return "gone";
      if (!response.ok) throw new Error(`events: HTTP ${response.status}`);
      const reader = response.body.getReader();
      const decoder = new TextDecoder();
      let buffer = "";
      let shutdown = false;
      for (;;) {
        const { value, done } = await reader.read();
        if (done) break;
        buffer += decoder.decode(value, { stream: true });
        // a lone CR at the end may be the first half of a CRLF
        const keep = buffer.endsWith("\r") ? 1 : 0;
        let text = buffer.slice(0, buffer.length - keep).replace(/\r\n?/g, "\n");
        const carry = buffer.slice(buffer.length - keep);
        const blocks = text.split("\n\n");
        buffer = blocks.pop() + carry;
        const batch = [];
        for (const block of blocks) {
          const event = parseBlock(block);
          if (event === null) continue;
          if (event.retry) retry = event.retry;
          if (event.type === "shutdown") {
            shutdown = true;
            continue;
          }
          if (event.seq) last = event.seq;
          batch.push(event);
        }
        if (batch.length) onBatch(batch);
      }
      return shutdown ? "shutdown" : "ended";
    }

    const finished = (async () => {
      while (!stopped) {
        let how;
        try {
          how = await once();
        } catch (error) {
          if (stopped) return;
          how = "error";
          if (onError) onError(error);
        }
        if (how === "ended" || how === "gone") return how;
        await new Promise((resolve) => setTimeout(resolve, retry));
      }
      return "stopped";
    })();
    return {
      finished,
      stop() {
        stopped = true;
        controller.abort();
      },
    };
  }

  function parseBlock(block) {
    let data = "";
    let type = "message";
    let seq = 0;
    let retry = 0;
    let hasData = false;
    for (const line of block.split("\n")) {
      if (!line || line.startsWith(":")) continue;
      const colon = line.indexOf(":");
      const field = colon < 0 ? line : line.slice(0, colon);
      let value = colon < 0 ? "" : line.slice(colon + 1);
      if (value.startsWith(" ")) value = value.slice(1);
      if (field === "data") {
        data += (hasData ? "\n" : "") + value;
        hasData = true;
      } else if (field === "event") type = value;
      else if (field === "id") seq = Number(value) || 0;
      else if (field === "retry") retry = Number(value) || 0;
    }
    if (!hasData) return retry ? { type: "retry", retry } : null;
    let payload;
    try {
      payload = JSON.parse(data);
    } catch (_) {
      payload = { text: data };
    }
    if (payload === null || typeof payload !== "object") payload = { value: payload };
    return { ...payload, type: payload.type || type, seq, retry };
  }

  function shortId(id) {
    return id.slice(0, 8);
  }

  function when(seconds) {
    if (!seconds) return "";
    return new Date(seconds * 1000).toLocaleString();
  }

  return { api, json, el, detailText, setupKey, askForKey, fileLink, followEvents, TERMINAL, shortId,
    when };
})();
