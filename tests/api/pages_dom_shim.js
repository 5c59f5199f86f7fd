// A DOM just big enough for the pages' `AVS.el`, `AVS_TARGETS.table` and `AVS_MEMORY`,
// serialised as HTML: loads common.js, targets.js and memory.js from the folder given last
// on the command line,
// then prints what the function read from stdin ({script, data}) returns for `data`
// (tests/api/test_pages_targets.py, test_pages_memory.py).
"use strict";
const vm = require("vm");
const fs = require("fs");
const escape = (s) => String(s).replace(/&/g, "&amp;").replace(/</g, "&lt;").replace(/>/g, "&gt;").replace(/"/g, "&quot;");
class Node {}
class Text extends Node {
  constructor(text) { super(); this.text = String(text); }
  get html() { return escape(this.text); }
}
class Element extends Node {
  constructor(tag) { super(); this.tag = tag; this.children = []; this.attributes = {}; this.className = ""; this.title = ""; }
  setAttribute(name, value) { this.attributes[name] = String(value); }
  append(...nodes) { this.children.push(...nodes.map((n) => (n instanceof Node ? n : new Text(n)))); }
  replaceChildren(...nodes) { this.children = []; this.append(...nodes); }
  set textContent(text) { this.children = [new Text(text)]; }
  get textContent() { return this.children.map((c) => (c instanceof Text ? c.text : c.textContent)).join(""); }
  get html() {
    const attrs = { ...(this.className ? { class: this.className } : {}), ...(this.title ? { title: this.title } : {}), ...this.attributes };
    const open = [this.tag, ...Object.entries(attrs).map(([k, v]) => `${k}="${escape(v)}"`)].join(" ");
    return `<${open}>${this.children.map((c) => c.html).join("")}</${this.tag}>`;
  }
}
globalThis.Node = Node;
globalThis.document = { createElement: (tag) => new Element(tag), createTextNode: (text) => new Text(text) };
for (const name of ["common.js", "targets.js", "memory.js"]) {
  vm.runInThisContext(fs.readFileSync(`${process.argv.at(-1)}/${name}`, "utf8"), { filename: name });
}
const input = JSON.parse(fs.readFileSync(0, "utf8"));
process.stdout.write(vm.runInThisContext(`(${input.script})`)(input.data));
