"""The web page in headless Chromium: it loads, an FK and an IK request round-trip, and a
scenario run completes with its plots shown (the page's scripted ``?demo=1`` mode)."""

from __future__ import annotations

import json
import re
import subprocess
from html.parser import HTMLParser
from urllib.parse import urlencode

import numpy as np
import pytest
from browser import CHROMIUM
from service_server import SCENARIOS, Server

from lynxplan.arm import load_arm

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="chromium is not installed")


class _Elements(HTMLParser):
    """Attributes and text of elements by id, and every <img>."""

    def __init__(self) -> None:
        super().__init__()
        self.by_id: dict[str, dict[str, str]] = {}
        self.images: list[dict[str, str]] = []
        self.body: dict[str, str] = {}
        self._open: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = {k: v or "" for k, v in attrs}
        if tag == "img":
            self.images.append(values)
        if tag == "body":
            self.body = values
        if "id" in values:
            self.by_id[values["id"]] = {**values, "text": ""}
            self._open.append(values["id"])
        else:
            self._open.append("")

    def handle_endtag(self, tag: str) -> None:
        if self._open and tag not in ("img", "input", "br", "link", "meta"):
            self._open.pop()

    def handle_data(self, data: str) -> None:
        for element in reversed(self._open):
            if element:
                self.by_id[element]["text"] += data
                break


def dump_dom(url: str, profile) -> str:
    """The DOM of ``url`` after its scripts ran (headless Chromium, virtual time)."""
    command = [
        str(CHROMIUM), "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        f"--user-data-dir={profile}", "--virtual-time-budget=900000", "--dump-dom", url,
    ]  # fmt: skip
    return subprocess.run(command, capture_output=True, text=True, timeout=240, check=True).stdout


def test_api_docs_render_offline(server: Server, tmp_path) -> None:
    page = _Elements()
    page.feed(dump_dom(f"{server.url}/docs", tmp_path / "profile"))
    assert page.body.get("data-rendered") == "yes"
    text = page.by_id["endpoints"]["text"]
    for path in ("/ik", "/fk", "/check", "/trajectory", "/plan", "/runs"):
        assert path in text, path


def test_page_fk_ik_and_a_run_with_plots(server: Server, tmp_path) -> None:
    q_deg = [40.0, 70.0, -80.0, 60.0, 30.0]
    params = {"demo": "1", "q": ",".join(map(str, q_deg)),
              "scenario": (SCENARIOS / "free_motion.yaml").read_text()}  # fmt: skip
    url = f"{server.url}/?{urlencode(params)}"
    dom = dump_dom(url, tmp_path / "profile")
    page = _Elements()
    page.feed(dom)
    assert page.body.get("data-demo") == "done", dom[-3000:]
    assert page.by_id["version"]["text"].startswith("v")
    assert page.by_id["fk-result"].get("data-status") == "ok", page.by_id["fk-result"]
    arm = load_arm()
    T = arm.fk(np.radians(q_deg))
    shown = [float(x) for x in re.findall(r"-?\d+\.\d+", page.by_id["fk-result"]["text"])[:3]]
    np.testing.assert_allclose(shown, T[:3, 3] * 1000, atol=0.01)
    assert page.by_id["ik-result"].get("data-status") == "ok", page.by_id["ik-result"]
    q_ik = np.array(json.loads(page.by_id["ik-result"]["data-q"]))
    reached = arm.fk(q_ik)
    np.testing.assert_allclose(reached[:3, 3], T[:3, 3], atol=1e-5)  # target typed in as mm
    np.testing.assert_allclose(reached[:3, 2], T[:3, 2], atol=1e-5)
    assert page.by_id["run-state"]["text"] == "succeeded", page.by_id["run-summary"]
    assert "every expectation holds" in page.by_id["run-summary"]["text"]
    plots = [img for img in page.images if img.get("alt", "").endswith(".png")]
    assert plots and all(int(img.get("data-loaded", "0")) > 100 for img in plots), plots
    links = page.by_id["artifacts"]["text"]
    assert "report.json" in links and "trajectory.csv" in links


def test_page_and_static_files_are_served_without_a_cdn(server: Server) -> None:
    import httpx

    html = httpx.get(server.url + "/").text
    assert "/static/app.js" in html and "http" not in html.replace("http-equiv", "")
    script = httpx.get(server.url + "/static/app.js")
    assert script.status_code == 200 and "javascript" in script.headers["content-type"]
    assert not re.search(r"(https?:)?//[a-z0-9.-]+\.[a-z]{2,}/", script.text)  # no remote URL
    assert httpx.get(server.url + "/static/..%2Fapp.py").status_code == 404
