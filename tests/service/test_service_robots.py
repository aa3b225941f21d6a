"""The service as a user meets it (issue 34 section 6): every built-in robot through the
kinematics endpoints (5, 6 and 7 joints, arrays checked against each robot's joint count), and
what ``lynxplan serve`` says and where it keeps its data."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import httpx
import numpy as np
import pytest
from service_server import REPO, START_TIMEOUT, free_port

import lynxplan

ROBOTS = ("al5", "panda", "so100", "so101", "ur10", "ur5")
#: Pose agreement between the service and Pinocchio's own FK, in [m] (and unitless rotation).
FK_TOLERANCE = 1e-12
#: IK answers: the position reached by Pinocchio's FK of the returned q, in [m].
IK_TOLERANCE = 1e-6


def test_robots_lists_every_built_in_robot(http: httpx.Client) -> None:
    robots = {r["name"]: r for r in http.get("/robots").json()["robots"]}
    assert tuple(robots) == ROBOTS
    for name in ROBOTS:
        described = http.get(f"/robots/{name}").json()
        assert described == robots[name]
        model = lynxplan.load_robot(name)
        assert described["dof"] == model.nq == len(described["joints"])
        lower = [j["lower"] for j in described["joints"]]
        assert np.allclose(lower, model.limits.lower, atol=1e-12)


@pytest.mark.parametrize("name", ROBOTS[1:])
def test_fk_and_ik_of_every_robot_agree_with_pinocchio(http: httpx.Client, name: str) -> None:
    import pinocchio as pin

    model = lynxplan.load_robot(name)
    rng = np.random.default_rng(7)
    q = rng.uniform(model.limits.lower, model.limits.upper, size=(3, model.nq)) * 0.8
    answer = http.post("/fk", json={"robot": name, "q": q.tolist()})
    assert answer.status_code == 200, answer.text
    T = np.array(answer.json()["T"])
    data = model.model.createData()
    for qi, Ti in zip(q, T, strict=True):
        pin.framesForwardKinematics(model.model, data, qi)
        expected = data.oMf[model.tool_frame_id].homogeneous
        assert np.abs(Ti - expected).max() < FK_TOLERANCE
    # one pose: every branch listed, the selected one reaches the pose
    single = http.post("/ik", json={"robot": name, "T": T[0].tolist()}).json()
    assert single["solutions"] and single["selected"] is not None, single
    pin.framesForwardKinematics(model.model, data, np.array(single["q"]))
    assert np.linalg.norm(data.oMf[model.tool_frame_id].translation - T[0][:3, 3]) < IK_TOLERANCE
    # a batch: the branch slots named, each valid branch reaching its pose
    batch = http.post("/ik", json={"robot": name, "T": T.tolist()}).json()
    assert batch["count"] == 3 and len(batch["branch_names"]) == np.shape(batch["q"])[1]
    for qs, valid, Ti in zip(batch["q"], batch["valid"], T, strict=True):
        for qb in np.array(qs, dtype=float)[np.array(valid, dtype=bool)]:
            pin.framesForwardKinematics(model.model, data, qb)
            reached = data.oMf[model.tool_frame_id].translation
            assert np.linalg.norm(reached - Ti[:3, 3]) < IK_TOLERANCE


@pytest.mark.parametrize(("name", "joints"), [("ur5", 6), ("panda", 7), ("so100", 5)])
def test_arrays_are_checked_against_the_robots_joints(
    http: httpx.Client, name: str, joints: int
) -> None:
    """A 5-joint q for a 6-joint arm (and so on) is a 422 naming the field, the shape the robot
    takes and the shape given, in JSON and in binary."""
    wrong = joints + 1
    fk = http.post("/fk", json={"robot": name, "q": [[0.0] * wrong]})
    assert fk.status_code == 422 and fk.json()["field"] == "q", fk.text
    expected = f"({joints},) or (N, {joints}) for {name} ({joints} joints). Got: (1, {wrong})"
    assert expected in fk.json()["detail"]
    raw = http.post(f"/fk?robot={name}", content=bytes(8 * 2 * wrong), headers={
        "Content-Type": "application/octet-stream", "X-Shape": f"2,{wrong}"})  # fmt: skip
    assert raw.status_code == 422 and f"Got: (2, {wrong})" in raw.json()["detail"], raw.text
    T = np.eye(4).tolist()
    ik = http.post("/ik", json={"robot": name, "T": T, "q_reference": [0.0] * wrong})
    assert ik.status_code == 422 and ik.json()["field"] == "q_reference", ik.text
    assert f"({joints},)" in ik.json()["detail"] and f"Got: ({wrong},)" in ik.json()["detail"]


def test_motion_endpoints_name_the_robots_they_serve(http: httpx.Client) -> None:
    """/check, /trajectory, /plan and /view serve the 5-joint robots; a 6-joint one is a 422
    naming the robot, its joints and the robots served (never a 500 on a shape)."""
    for path, body in (("/check", {"q": [0.0] * 6}), ("/plan", {"start": [0.0] * 6,
                       "goal": [0.1] * 6}), ("/trajectory", {"waypoints": [[0.0] * 6] * 2}),
                       ("/view", {"q": [0.0] * 6})):  # fmt: skip
        answer = http.post(path, json={"robot": "ur5", **body})
        assert answer.status_code == 422 and answer.json()["field"] == "robot", answer.text
        assert "ur5 has 6 joints" in answer.json()["detail"] and "so101" in answer.json()["detail"]


def test_other_endpoints_take_every_robot(http: httpx.Client) -> None:
    q = [0.1, 0.2, -0.3, 0.2, 0.1]
    check = http.post("/check", json={"robot": "so101", "q": [q], "obstacles": [
        {"type": "sphere", "centre": [0.3, 0.0, 0.1], "radius": 0.02}]})  # fmt: skip
    assert check.status_code == 200 and check.json()["min_clearance"][0] > 0, check.text
    motion = http.post("/trajectory", json={"robot": "so100", "waypoints": [q, [0.0] * 5]})
    assert motion.status_code == 200, motion.text


def start_default_serve(tmp_path) -> tuple[subprocess.Popen, str, dict]:
    """``lynxplan serve`` as a user starts it: no --data-dir, from another folder."""
    port = free_port()
    env = {**os.environ, "PYTHONPATH": str(REPO), "XDG_DATA_HOME": str(tmp_path / "xdg")}
    (tmp_path / "cwd").mkdir()
    log = (tmp_path / "out.log").open("wb")
    process = subprocess.Popen(
        [sys.executable, "-m", "lynxplan.cli", "serve", "--port", str(port)],
        stdout=log, stderr=subprocess.STDOUT, cwd=tmp_path / "cwd", env=env,
    )  # fmt: skip
    return process, f"http://127.0.0.1:{port}", env


def test_serve_says_where_it_is_and_keeps_data_in_the_users_folder(tmp_path) -> None:
    process, url, _ = start_default_serve(tmp_path)
    try:
        deadline = time.monotonic() + START_TIMEOUT
        while time.monotonic() < deadline and process.poll() is None:
            try:
                if httpx.get(url + "/health", timeout=1.0).status_code == 200:
                    break
            except httpx.HTTPError:
                time.sleep(0.2)
        assert httpx.get(url + "/health").status_code == 200
    finally:
        process.terminate()
        process.wait(30)
    printed = (tmp_path / "out.log").read_text()
    data = tmp_path / "xdg" / "lynxplan"
    assert f"{url}/" in printed, printed
    assert f"data folder: {data}" in printed
    assert "access: no token" in printed and "run workers: 1" in printed
    assert (data / "lynxplan.sqlite3").is_file()
    assert not any((tmp_path / "cwd").iterdir())  # nothing in the current folder


def test_the_repository_tracks_no_service_data() -> None:
    tracked = subprocess.run(["git", "ls-files", "lynxplan-data"], cwd=REPO, capture_output=True,
                             text=True, check=True).stdout  # fmt: skip
    assert tracked == ""
    ignored = subprocess.run(["git", "check-ignore", "-q", "lynxplan-data/x.sqlite3"], cwd=REPO)
    assert ignored.returncode == 0


def test_serve_help_documents_access_and_tokens() -> None:
    done = subprocess.run([sys.executable, "-m", "lynxplan.cli", "serve", "--help"],
                          capture_output=True, text=True, timeout=60, cwd=REPO)  # fmt: skip
    assert done.returncode == 0
    text = " ".join(done.stdout.split())
    for phrase in ("one shared token", "name:token", "--allowed-host", "--cors-origin",
                   "/openapi.json", "--header-timeout", "--max-connections"):  # fmt: skip
        assert phrase in text, phrase
