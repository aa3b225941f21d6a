"""The service under attack (issue 35 sections 2, 3, 5), against real ``lynxplan serve``
processes: no file of the server's disk opened on a caller's word, URDF uploads confined to the
run's folder, errors without server paths, Host/Origin/Content-Type checks, slow clients, and
runs owned by named tokens."""

from __future__ import annotations

import base64
import socket
from collections.abc import Iterator

import httpx
import pytest
import yaml
from service_server import REPO, SCENARIOS, Server

PROBLEM = "application/problem+json"
ALICE = "alice-token-0123456789"
BOB = "bob-token-0123456789ab"
ORIGIN = "https://planner.example"
Q0 = [0.5, 0.5, -0.5, 0.5, 0.5]


def problem(response: httpx.Response, status: int, field: str | None) -> str:
    """The detail of a problem+json answer with this status and field."""
    assert response.status_code == status, response.text
    assert response.headers["content-type"].startswith(PROBLEM)
    body = response.json()
    assert body.get("field") == field, body
    assert "Traceback" not in response.text
    return str(body["detail"])


@pytest.fixture(scope="module")
def guarded(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """Named tokens (alice, bob), one extra host name and one allowed web origin."""
    folder = tmp_path_factory.mktemp("security")
    tokens = folder / "tokens"
    tokens.write_text(f"# name:token\nalice:{ALICE}\nbob:{BOB}\n")
    server = Server(folder / "data", "--token-file", str(tokens), "--allowed-host",
                    "planner.lan", "--cors-origin", ORIGIN)  # fmt: skip
    yield server
    server.stop()


def as_(token: str) -> dict[str, str]:
    return {"Authorization": f"Bearer {token}"}


def trajectory_scenario() -> dict:
    return yaml.safe_load((SCENARIOS / "straight_line.yaml").read_text())


# -- 2. files ----------------------------------------------------------------------------------
@pytest.mark.parametrize("endpoint", ["/fk", "/ik", "/check"])
def test_a_robot_name_is_never_a_path(http: httpx.Client, endpoint: str) -> None:
    body = {"q": Q0, "T": [[1, 0, 0, 0.2], [0, 1, 0, 0], [0, 0, 1, 0.1], [0, 0, 0, 1]]}
    details = {}
    for name in ("/etc/passwd", "/etc/no-such-file-here", "../../../../etc/shadow",
                 str(REPO / "urdf" / "lynxmotion_al5.urdf")):  # fmt: skip
        details[name] = problem(http.post(endpoint, json={**body, "robot": name}), 404, "robot")

    # the same answer whether the path exists or not: only the caller's own value differs (the
    # server echoes at most 40 characters of it, so the comparison does too, wherever the checkout)
    def shown(name: str) -> str:
        return name if len(name) <= 40 else name[:40] + "..."

    assert len({detail.replace(shown(name), "X") for name, detail in details.items()}) == 1
    assert "al5, panda, so100, so101, ur10, ur5" in details["/etc/passwd"]


@pytest.mark.parametrize("name", ["/etc/passwd", "../../../../etc/shadow", "/etc/nothing"])
def test_a_run_cannot_name_a_server_file_as_its_robot(http: httpx.Client, name: str) -> None:
    scenario = {**trajectory_scenario(), "robot": {"name": name}}
    detail = problem(http.post("/runs", json=scenario), 422, "robot.name")
    assert "unknown robot" in detail and "al5, panda, so100, so101, ur10, ur5" in detail
    urdf = {**trajectory_scenario(), "robot": {"urdf": name}}
    problem(http.post("/runs", json=urdf), 422, "robot.urdf")


def bundle(urdf: str, extra: dict[str, bytes] | None = None, **robot: str) -> dict:
    files = {"arm.urdf": urdf.encode(), **(extra or {})}
    return {
        "scenario": {**trajectory_scenario(), "robot": {"urdf": "arm.urdf", **robot}},
        "files": {name: base64.b64encode(data).decode() for name, data in files.items()},
    }


TETRAHEDRON = b"""solid t
facet normal 0 0 1
outer loop
vertex 0 0 0
vertex 0.01 0 0
vertex 0 0.01 0
endloop
endfacet
endsolid t
"""


def al5_with_mesh(filename: str) -> str:
    """The AL5 URDF with a visual mesh ``filename`` on its base link."""
    text = (REPO / "urdf" / "lynxmotion_al5.urdf").read_text()
    visual = f'<visual><geometry><mesh filename="{filename}"/></geometry></visual>'
    head, sep, tail = text.partition("</link>")
    return head + visual + sep + tail


def test_an_uploaded_urdf_with_its_mesh_runs_in_the_runs_own_folder(
    server: Server, http: httpx.Client
) -> None:
    body = bundle(al5_with_mesh("meshes/tip.stl"), {"meshes/tip.stl": TETRAHEDRON})
    submitted = http.post("/runs", params={"quick": True}, json=body)
    assert submitted.status_code == 202, submitted.text
    run_id = submitted.json()["id"]
    run = http.get(f"/runs/{run_id}", params={"wait": 60}).json()
    assert run["state"] == "succeeded" and run["ok"], run
    stored = server.data_dir / "runs" / run_id / "files"
    assert (stored / "meshes" / "tip.stl").read_bytes() == TETRAHEDRON
    # the stored URDF names the mesh by its path inside the run's folder, nothing else
    assert f'filename="{stored / "meshes" / "tip.stl"}"' in (stored / "arm.urdf").read_text()
    assert str(server.data_dir) not in http.get(f"/runs/{run_id}").text


@pytest.mark.parametrize(
    ("mesh", "files"),
    [
        ("/etc/passwd", {}),
        ("file:///etc/passwd", {}),
        ("../../../../etc/passwd", {}),
        ("package://al5/meshes/missing.stl", {}),
        ("meshes/tip.stl", {"../tip.stl": TETRAHEDRON}),
        ("meshes/tip.stl", {"/abs/tip.stl": TETRAHEDRON}),
    ],
)
def test_an_upload_never_reaches_outside_its_folder(
    server: Server, http: httpx.Client, mesh: str, files: dict[str, bytes]
) -> None:
    before = set((server.data_dir / "runs").iterdir())
    response = http.post("/runs", json=bundle(al5_with_mesh(mesh), files))
    field = problem(response, 422, response.json().get("field"))
    assert response.json()["field"].startswith("files."), field
    assert str(server.data_dir) not in response.text
    assert set((server.data_dir / "runs").iterdir()) == before  # nothing left behind


def test_the_upload_size_is_bounded(server: Server, http: httpx.Client) -> None:
    # the session server takes 32 MiB of files by default (--max-upload)
    big = {"meshes/big.stl": bytes(int(32.5 * 1024**2))}
    before = set((server.data_dir / "runs").iterdir())
    response = http.post("/runs", json=bundle(al5_with_mesh("meshes/big.stl"), big))
    assert "exceed the limit of 33554432 bytes" in problem(response, 413, "files")
    assert set((server.data_dir / "runs").iterdir()) == before


def test_a_failed_run_names_its_own_file_never_a_server_path(
    server: Server, http: httpx.Client
) -> None:
    broken = '<robot name="x"><link name="a"/><joint name="j" type="revolute"><parent link="a"/>' \
        '<child link="nowhere"/><axis xyz="0 0 1"/></joint></robot>'  # fmt: skip
    submitted = http.post("/runs", params={"quick": True}, json=bundle(broken))
    assert submitted.status_code == 202, submitted.text
    run = http.get(f"/runs/{submitted.json()['id']}", params={"wait": 60}).json()
    assert run["state"] == "failed", run
    assert "arm.urdf" in run["error"], run["error"]
    for text in (run["error"], str(run["summary"])):
        assert str(server.data_dir) not in text and "/runs/" not in text, text


# -- 3. cross-site -----------------------------------------------------------------------------
def test_foreign_host_names_are_refused(guarded: Server) -> None:
    for host in ("evil.example", "evil.example:8000", "127.0.0.1.evil.example"):
        response = httpx.post(guarded.url + "/fk", json={"q": Q0}, headers={
            **as_(ALICE), "Host": host})  # fmt: skip
        problem(response, 400, "Host")
    for host in (f"localhost:{guarded.port}", f"planner.lan:{guarded.port}", "127.0.0.1"):
        response = httpx.post(guarded.url + "/fk", json={"q": Q0}, headers={
            **as_(ALICE), "Host": host})  # fmt: skip
        assert response.status_code == 200, (host, response.text)


def test_cross_origin_requests_need_cors_origin(guarded: Server) -> None:
    evil = {**as_(ALICE), "Origin": "http://evil.example"}
    problem(httpx.post(guarded.url + "/fk", json={"q": Q0}, headers=evil), 403, "Origin")
    problem(httpx.get(guarded.url + "/runs", headers=evil), 403, "Origin")
    # the web page's own origin, and the allowed one (with its CORS headers and preflight)
    own = {**as_(ALICE), "Origin": guarded.url}
    assert httpx.post(guarded.url + "/fk", json={"q": Q0}, headers=own).status_code == 200
    allowed = httpx.post(guarded.url + "/fk", json={"q": Q0}, headers={**as_(ALICE),
                         "Origin": ORIGIN})  # fmt: skip
    assert allowed.status_code == 200 and allowed.headers["access-control-allow-origin"] == ORIGIN
    preflight = httpx.options(guarded.url + "/fk", headers={
        "Origin": ORIGIN, "Access-Control-Request-Method": "POST",
        "Access-Control-Request-Headers": "authorization, content-type"})  # fmt: skip
    assert preflight.status_code == 204
    assert "authorization" in preflight.headers["access-control-allow-headers"]


@pytest.mark.parametrize(
    ("path", "media"),
    [
        ("/runs", "text/plain"),
        ("/fk", "text/plain"),
        ("/ik", "text/plain;charset=UTF-8"),
        ("/check", "application/x-www-form-urlencoded"),
        ("/trajectory", "multipart/form-data; boundary=x"),
        ("/plan", "application/x-npy"),
        ("/runs", "application/octet-stream"),
    ],
)
def test_undocumented_content_types_are_415(http: httpx.Client, path: str, media: str) -> None:
    # a browser sends text/plain, form and multipart bodies cross-site without a preflight
    content = yaml.safe_dump(trajectory_scenario()) if path == "/runs" else '{"q": [0,0,0,0,0]}'
    before = http.get("/runs").json()["total"]
    response = http.post(path, content=content, headers={"Content-Type": media})
    problem(response, 415, "Content-Type")
    assert http.get("/runs").json()["total"] == before


# -- 5. ownership ------------------------------------------------------------------------------
def test_named_tokens_see_and_cancel_only_their_own_runs(guarded: Server) -> None:
    scenario = yaml.safe_load((SCENARIOS / "planning" / "u01_goal_in_jar.yaml").read_text())
    scenario["planner"].update(time_limit=30.0)
    url = guarded.url
    mine = httpx.post(url + "/runs", json=scenario, headers=as_(ALICE))
    assert mine.status_code == 202, mine.text
    run_id = mine.json()["id"]
    listed = httpx.get(url + "/runs", headers=as_(ALICE)).json()
    assert [item["id"] for item in listed["items"]] == [run_id] and listed["total"] == 1
    assert httpx.get(url + "/runs", headers=as_(BOB)).json() == {
        "items": [], "total": 0, "offset": 0, "limit": 50}  # fmt: skip
    for method, path in (("GET", f"/runs/{run_id}"), ("DELETE", f"/runs/{run_id}"),
                         ("GET", f"/runs/{run_id}/artifacts/report.json")):  # fmt: skip
        problem(httpx.request(method, url + path, headers=as_(BOB)), 404, "run_id")
    assert httpx.get(url + f"/runs/{run_id}", headers=as_(ALICE)).json()["id"] == run_id
    cancelled = httpx.delete(url + f"/runs/{run_id}", headers=as_(ALICE))
    assert cancelled.status_code in (200, 409), cancelled.text  # 409: it ended already


def test_open_paths_hold_no_data_and_the_rest_needs_a_token(guarded: Server) -> None:
    for path in ("/health", "/", "/docs", "/openapi.json", "/static/app.js"):
        assert httpx.get(guarded.url + path).status_code == 200, path
    for path in ("/robots", "/version", "/runs"):
        problem(httpx.get(guarded.url + path), 401, "Authorization")


# -- 5. slow clients ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def capped(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    server = Server(tmp_path_factory.mktemp("slow") / "data", "--max-connections", "100",
                    "--header-timeout", "5")  # fmt: skip
    yield server
    server.stop()


def slow_clients(server: Server, count: int) -> list[socket.socket]:
    """``count`` connections that started a request head and send it a byte at a time."""
    sockets = []
    for _ in range(count):
        sock = socket.create_connection(("127.0.0.1", server.port), timeout=60)
        for byte in b"GET /health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ":
            sock.send(bytes([byte]))
        sockets.append(sock)
    return sockets


def test_slowloris_connections_do_not_block_other_clients(capped: Server) -> None:
    sockets = slow_clients(capped, 64)
    try:
        for sock in sockets:
            sock.send(b"a")
        assert httpx.get(capped.url + "/health").json() == {"status": "ok"}
        assert httpx.post(capped.url + "/fk", json={"q": Q0}).status_code == 200
    finally:
        for sock in sockets:
            sock.close()


def test_a_request_head_that_never_ends_is_answered_408(capped: Server) -> None:
    (sock,) = slow_clients(capped, 1)
    with sock:
        answer = b""
        while chunk := sock.recv(4096):  # the server closes the connection after its answer
            answer += chunk
    assert answer.startswith(b"HTTP/1.1 408 "), answer


def test_connections_beyond_the_cap_are_503_and_served_again_after(capped: Server) -> None:
    sockets = slow_clients(capped, 100)
    try:
        assert httpx.get(capped.url + "/health").status_code == 503
    finally:
        for sock in sockets:
            sock.close()
    for _ in range(50):  # the server notices the closed sockets as it reads them
        if (status := httpx.get(capped.url + "/health").status_code) == 200:
            break
    assert status == 200
