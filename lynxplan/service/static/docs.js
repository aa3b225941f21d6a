// API reference rendered from /openapi.json on this server (no CDN: the network may be closed).
"use strict";
async function loadSpec() {
  const token = document.getElementById("token").value || sessionStorage.getItem("lynxplan-token");
  const response = await fetch("/openapi.json", { headers: token ? { Authorization: "Bearer " + token } : {} });
  if (!response.ok) throw new Error(response.status + ": " + (await response.text()));
  return response.json();
}

function element(tag, text, className) {
  const el = document.createElement(tag);
  if (text !== undefined) el.textContent = text;
  if (className) el.className = className;
  return el;
}

function render(spec) {
  const root = document.getElementById("endpoints");
  root.innerHTML = "";
  document.getElementById("version").textContent = spec.info.title + " " + spec.info.version;
  root.appendChild(element("p", spec.info.description || ""));
  for (const [path, methods] of Object.entries(spec.paths)) {
    for (const [method, operation] of Object.entries(methods)) {
      const box = element("div", undefined, "endpoint");
      box.dataset.path = path;
      const title = element("h3");
      title.appendChild(element("span", method.toUpperCase(), "method"));
      title.appendChild(element("code", path));
      box.appendChild(title);
      if (operation.summary) box.appendChild(element("p", operation.summary));
      const parameters = (operation.parameters || []).map((p) => p.name + " (" + p.in + ")");
      if (parameters.length) box.appendChild(element("p", "parameters: " + parameters.join(", ")));
      const body = operation.requestBody && operation.requestBody.content;
      if (body) {
        box.appendChild(element("p", "body: " + Object.keys(body).join(", ")));
        const json = body["application/json"];
        if (json && json.schema) box.appendChild(element("pre", JSON.stringify(json.schema, null, 2), "schema"));
      }
      root.appendChild(box);
    }
  }
  document.body.dataset.rendered = "yes";
}

loadSpec().then(render).catch((e) => {
  document.getElementById("endpoints").textContent = "cannot load /openapi.json: " + e.message;
});
