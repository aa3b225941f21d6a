// lynxplan web page: plain JavaScript, no network beyond this server (no CDN).
"use strict";
const $ = (id) => document.getElementById(id);
const DEG = Math.PI / 180;
const state = { robot: null, joints: [] };

function headers(extra) {
  const h = Object.assign({}, extra || {});
  const token = $("token").value || sessionStorage.getItem("lynxplan-token");
  if (token) { h["Authorization"] = "Bearer " + token; sessionStorage.setItem("lynxplan-token", token); }
  return h;
}

async function api(method, path, body, type) {
  const init = { method, headers: headers(body === undefined ? {} : { "Content-Type": type || "application/json" }) };
  if (body !== undefined) init.body = type ? body : JSON.stringify(body);
  const response = await fetch(path, init);
  const text = await response.text();
  let data = text;
  try { data = JSON.parse(text); } catch (e) { /* HTML or plain text */ }
  if (!response.ok) {
    const detail = data && data.detail ? data.detail + (data.field ? " (" + data.field + ")" : "") : text;
    throw new Error(response.status + ": " + detail);
  }
  return data;
}

function show(id, text, error) {
  const el = $(id);
  el.textContent = text;
  el.classList.toggle("error", !!error);
  el.dataset.status = error ? "error" : "ok";
}

function fmt(values, digits) { return values.map((v) => (v === null ? "nan" : v.toFixed(digits))).join("  "); }

function jointsRad() { return state.joints.map((input) => parseFloat(input.value) * DEG); }

async function loadRobots() {
  const version = await api("GET", "/version");
  $("version").textContent = "v" + version.lynxplan;
  const robots = (await api("GET", "/robots")).robots;
  $("robot").innerHTML = "";
  for (const r of robots) {
    const option = document.createElement("option");
    option.value = r.name; option.textContent = r.name + " (" + r.family + ")";
    $("robot").appendChild(option);
  }
  selectRobot(robots[0]);
  $("robot").onchange = () => selectRobot(robots.find((r) => r.name === $("robot").value));
}

function selectRobot(robot) {
  state.robot = robot;
  $("joints").innerHTML = "";
  state.joints = robot.joints.map((joint) => {
    const input = document.createElement("input");
    input.title = joint.name + " [" + (joint.lower / DEG).toFixed(0) + ", " + (joint.upper / DEG).toFixed(0) + "] deg";
    input.value = (((joint.lower + joint.upper) / 2) / DEG).toFixed(1);
    $("joints").appendChild(input);
    return input;
  });
}

async function fk() {
  try {
    const answer = await api("POST", "/fk", { robot: state.robot.name, q: jointsRad() });
    const T = answer.T;
    show("fk-result", "position [mm]: " + fmt([T[0][3], T[1][3], T[2][3]].map((v) => v * 1000), 2) +
      "\napproach: " + fmt([T[0][2], T[1][2], T[2][2]], 4) +
      "\nverification residual (vs Pinocchio): " + answer.residual.toExponential(2));
    ["px", "py", "pz"].forEach((id, i) => { $(id).value = (T[i][3] * 1000).toFixed(3); });
    ["ax", "ay", "az"].forEach((id, i) => { $(id).value = T[i][2].toFixed(6); });
    return answer;
  } catch (e) { show("fk-result", e.message, true); return null; }
}

async function ik() {
  const position = ["px", "py", "pz"].map((id) => parseFloat($(id).value) / 1000);
  const approach = ["ax", "ay", "az"].map((id) => parseFloat($(id).value));
  try {
    const answer = await api("POST", "/ik", { robot: state.robot.name, position, approach, q_reference: jointsRad() });
    if (answer.q === null) { show("ik-result", "no branch within the joint limits", true); return answer; }
    answer.q.forEach((v, i) => { state.joints[i].value = (v / DEG).toFixed(3); });
    show("ik-result", "branch " + answer.branch + ": q [deg] " + fmt(answer.q.map((v) => v / DEG), 3) +
      "\nposition residual: " + answer.position_residual.toExponential(2) + " m" +
      ", orientation residual: " + answer.orientation_residual.toExponential(2) + " rad");
    $("ik-result").dataset.q = JSON.stringify(answer.q);
    return answer;
  } catch (e) { show("ik-result", e.message, true); return null; }
}

async function view() {
  try {
    $("viewer").srcdoc = await api("POST", "/view", { robot: state.robot.name, q: jointsRad() });
    $("viewer").dataset.status = "ok";
  } catch (e) { show("ik-result", e.message, true); }
}

async function runScenario(text) {
  $("artifacts").innerHTML = ""; $("plots").innerHTML = "";
  show("run-summary", "");
  const quick = $("quick").checked ? "true" : "false";
  const json = text.trim().startsWith("{");
  let record;
  try {
    record = await api("POST", "/runs?quick=" + quick, text, json ? "application/json" : "application/yaml");
  } catch (e) { show("run-summary", e.message, true); $("run-state").textContent = "rejected"; return; }
  while (true) {
    $("run-state").textContent = record.state;
    $("run-progress").value = record.progress;
    if (["succeeded", "failed", "cancelled", "interrupted"].includes(record.state)) break;
    record = await api("GET", "/runs/" + record.id + "?wait=2");  // long poll
  }
  $("run-state").dataset.id = record.id;
  if (record.state !== "succeeded") { show("run-summary", record.error || record.state, true); return record; }
  show("run-summary", record.summary + (record.ok ? "\nevery expectation holds" : "\nfailed: " + record.error), !record.ok);
  for (const name of record.artifacts) {
    const url = "/runs/" + record.id + "/artifacts/" + name;
    const item = document.createElement("li");
    const link = document.createElement("a");
    link.textContent = name; link.download = name.split("/").pop();
    item.appendChild(link);
    $("artifacts").appendChild(item);
    const response = await fetch(url, { headers: headers() });
    const blob = await response.blob();
    const objectUrl = URL.createObjectURL(blob);
    link.href = objectUrl;
    if (name.endsWith(".png")) {
      const img = document.createElement("img");
      img.alt = name;
      img.onload = () => { img.dataset.loaded = String(img.naturalWidth); };
      img.src = objectUrl;
      $("plots").appendChild(img);
    }
  }
  return record;
}

async function demo(params) {
  // Scripted use for tests and demos: /?demo=1&q=deg,deg,...&scenario=<url of a YAML>
  const q = (params.get("q") || "").split(",").filter((s) => s).map(parseFloat);
  q.forEach((v, i) => { if (state.joints[i]) state.joints[i].value = String(v); });
  await fk();
  q.forEach((v, i) => { if (state.joints[i]) state.joints[i].value = String(v + 5); });
  await ik();
  if (params.get("view") === "1") await view();
  const scenario = params.get("scenario");
  if (scenario) {
    $("scenario").value = scenario;
    await runScenario(scenario);
  }
  document.body.dataset.demo = "done";
}

function init() {
  $("token").value = sessionStorage.getItem("lynxplan-token") || "";
  $("fk-button").onclick = fk;
  $("ik-button").onclick = ik;
  $("view-button").onclick = view;
  $("run-button").onclick = () => runScenario($("scenario").value);
  $("scenario-file").onchange = async (event) => {
    const file = event.target.files[0];
    if (file) $("scenario").value = await file.text();
  };
  loadRobots().then(() => {
    const params = new URLSearchParams(location.search);
    if (params.get("demo") === "1") return demo(params);
  }).catch((e) => show("fk-result", e.message, true));
}

init();
