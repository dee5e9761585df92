"""The design explorer (GET /): served offline by the service, and driven in a real browser.

The route tests run in-process. The browser tests drive Debian's ``chromium`` through
``chromedriver`` (selenium) against a real ``gearengine serve`` with API keys on: fill the form
and analyse, see a field error for a wrong unit, run a small envelope and open a map point,
read a measured signal loaded from a CSV file. Every request the page makes is recorded
(Chrome's performance log, CDP Network events) and must stay on the server's origin. Without
chromium, chromedriver or selenium the browser tests skip, saying which is missing; with
GEARCHAOS_BROWSER_TESTS=required (set by .ci/run after it installs the browser) they fail
instead.

GEARCHAOS_EXPLORER_SCREENSHOTS=DIR saves the README's screenshots (explorer-verdict.png,
explorer-field-error.png, explorer-envelope.png, explorer-signal.png, ...) into DIR,
GEARCHAOS_EXPLORER_WIDTH=800 at another window width (default 1280).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from fastapi.testclient import TestClient

from gearengine.model.design import EXAMPLE_DESIGN
from service.api.routes.explorer import GEOMETRY_EXAMPLE, PAGE_DIR, plotly_js
from service.core.config import Settings
from service.main import create_app
from tests.conftest import ROOT, Server

KEY = "explorer-test-key"
CHROMIUM = ("/usr/bin/chromium", "chromium", "chromium-browser")
CHROMEDRIVER = ("/usr/bin/chromedriver", "chromedriver")
CHROME_FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--window-size=1280,900",
]


# ---------------------------------------------------------------------------- in-process


def test_root_serves_the_explorer_with_links_to_the_docs(client: TestClient) -> None:
    page = client.get("/")
    assert page.status_code == 200 and page.headers["content-type"].startswith("text/html")
    assert 'href="/docs"' in page.text and 'href="/redoc"' in page.text
    assert client.get("/explorer/explorer.js").headers["content-type"].startswith("text/javascript")
    assert client.get("/explorer/explorer.css").headers["content-type"].startswith("text/css")
    assert client.get("/explorer/index.html").status_code == 404  # only the listed files
    assert client.get("/explorer/..%2Fmain.py").status_code == 404


def test_plotly_is_served_from_the_python_environment(client: TestClient) -> None:
    path = plotly_js()
    assert path is not None, "plotly is a dependency: pip install -e ."
    r = client.get("/static/plotly.min.js")
    assert r.status_code == 200 and r.content == path.read_bytes()


def test_the_form_is_prefilled_with_the_readme_design(client: TestClient) -> None:
    defaults = client.get("/explorer/defaults.json").json()
    assert defaults["direct"] == EXAMPLE_DESIGN
    geometry = json.loads((ROOT / "examples/design-geometry.json").read_text())["design"]
    assert defaults["geometry"] == GEOMETRY_EXAMPLE == geometry


def test_the_page_names_no_other_host() -> None:
    """No CDN, no font service: every URL in the page's files is a path on this server."""
    for path in PAGE_DIR.iterdir():
        urls = re.findall(r"""(?:https?:)?//[\w.-]+""", path.read_text())
        assert urls == [], (path.name, urls)


def test_the_page_is_open_when_api_keys_are_on(tmp_path: Path) -> None:
    settings = Settings(data_dir=tmp_path, workers=0, api_keys=KEY)
    with TestClient(create_app(settings)) as c:
        assert c.get("/").status_code == 200
        assert c.get("/static/plotly.min.js").status_code == 200
        assert c.post("/v1/analyses", json={"design": EXAMPLE_DESIGN}).status_code == 401


# ---------------------------------------------------------------------------- the browser


def _find(candidates: tuple[str, ...]) -> str | None:
    return next((p for p in map(shutil.which, candidates) if p), None)


def _browser_missing() -> str | None:
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium is not installed (pip install -e '.[test]')"
    if _find(CHROMIUM) is None:
        return "no chromium on PATH (apt-get install chromium chromium-driver)"
    if _find(CHROMEDRIVER) is None:
        return "no chromedriver on PATH (apt-get install chromium-driver)"
    return None


@pytest.fixture(scope="module")
def keyed_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    missing = _browser_missing()
    if missing:
        if os.environ.get("GEARCHAOS_BROWSER_TESTS") == "required":
            pytest.fail(f"browser tests required but {missing}")
        pytest.skip(f"browser tests skipped: {missing}")
    env = {"GEARCHAOS_API_KEYS": KEY, "GEARCHAOS_SWEEP_CHUNK_POINTS": "4"}
    srv = Server(tmp_path_factory.mktemp("explorer") / "data", env)
    yield srv
    srv.stop()


class Page:
    """A Chromium tab on the explorer, recording every request the page makes."""

    def __init__(self, server: Server) -> None:
        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service

        os.environ.setdefault("SE_OFFLINE", "true")  # never let selenium fetch a driver
        options = webdriver.ChromeOptions()
        options.binary_location = _find(CHROMIUM) or ""
        self.profile = tempfile.mkdtemp(prefix="gearchaos-chromium-")
        for flag in [*CHROME_FLAGS, f"--user-data-dir={self.profile}"]:
            options.add_argument(flag)
        options.set_capability("goog:loggingPrefs", {"performance": "ALL"})
        self.driver = webdriver.Chrome(service=Service(_find(CHROMEDRIVER)), options=options)
        self.driver.set_script_timeout(30)
        self.server = server
        self.urls: list[str] = []

    def open(self, key: str | None = KEY) -> None:
        width = int(os.environ.get("GEARCHAOS_EXPLORER_WIDTH", "1280"))
        self.driver.set_window_size(width, 900)
        self.driver.get("about:blank")
        self.driver.get_log("performance")  # Chrome's own start-up pages are not the explorer's
        self.driver.get(self.server.url + "/")
        self.wait(lambda d: d.execute_script("return document.body.dataset.ready === 'true'"))
        if key:
            self.field("api-key", by="id").send_keys(key)

    def wait(self, condition: Callable[[Any], Any], timeout: float = 90.0) -> Any:
        from selenium.webdriver.support.ui import WebDriverWait

        return WebDriverWait(self.driver, timeout, poll_frequency=0.1).until(condition)

    def field(self, key: str, by: str = "path") -> Any:
        from selenium.webdriver.common.by import By

        if by == "id":
            return self.driver.find_element(By.ID, key)
        return self.driver.find_element(By.CSS_SELECTOR, f'[data-path="{key}"]')

    def type(self, path: str, text: str) -> None:
        box = self.field(path)
        box.clear()
        box.send_keys(text)

    def text(self, css: str) -> str:
        from selenium.webdriver.common.by import By

        return self.driver.find_element(By.CSS_SELECTOR, css).text

    def figures_done(self) -> None:
        """The design's figures (those of #verdict) have loaded or failed."""
        self.wait(
            lambda d: d.execute_script(
                "return [...document.querySelectorAll('#verdict figure img')]"
                ".every(i => ['shown', 'failed'].includes(i.dataset.state))"
            )
        )

    def requested(self) -> list[str]:
        """URLs the page requested since the last call (CDP Network.requestWillBeSent)."""
        for entry in self.driver.get_log("performance"):
            message = json.loads(entry["message"])["message"]
            if message["method"] == "Network.requestWillBeSent":
                self.urls.append(message["params"]["request"]["url"])
        return self.urls

    def assert_same_origin(self) -> None:
        urls = self.requested()
        assert urls, "no request recorded: is the performance log on?"
        origin = self.server.url
        foreign = [
            u
            for u in urls
            if not (u == origin or u.startswith(origin + "/") or u.startswith("data:"))
            and not u.startswith("blob:" + origin + "/")
        ]
        assert foreign == [], foreign

    def show(self, css: str) -> None:
        """The page from its top, or from ``css`` when that is below the fold (one column)."""
        self.driver.execute_script(
            "window.scrollTo(0, 0); const e = document.querySelector(arguments[0]);"
            "if (e.getBoundingClientRect().top > innerHeight / 2) e.scrollIntoView()",
            css,
        )

    def screenshot(self, name: str, height: int | None = None) -> None:
        target = os.environ.get("GEARCHAOS_EXPLORER_SCREENSHOTS")
        if not target:
            return
        if height:
            self.driver.set_window_size(self.driver.get_window_size()["width"], height)
        self.driver.save_screenshot(str(Path(target) / name))

    def close(self) -> None:
        self.driver.quit()
        shutil.rmtree(self.profile, ignore_errors=True)


@pytest.fixture
def page(keyed_server: Server) -> Iterator[Page]:
    p = Page(keyed_server)
    try:
        yield p
    finally:
        p.close()


def test_analyse_shows_the_verdict(page: Page) -> None:
    page.open()
    assert page.field("design.speed").get_attribute("value") == EXAMPLE_DESIGN["speed"]
    assert page.field("design.mesh.half_backlash").get_attribute("value") == "50 um"
    page.field("analyse", by="id").click()
    summary = page.wait(lambda d: page.text("#verdict-summary"))
    assert "1,500 rpm" in summary and "Melnikov" in summary
    facts = page.text("#verdict-facts")
    for label in ("Numerical class", "Largest Lyapunov exponent", "Stability margin",
                  "Melnikov speed windows", "Dynamic factor", "Contact"):  # fmt: skip
        assert label in facts
    # 40 N*m is above the pair's critical torque: no Melnikov windows, and the facts say why
    assert "not applicable above T_crit = 9.62 N*m" in facts and "µm peak to peak" in facts
    assert "Critical torque" in facts and "9.62 N·m" in facts
    page.figures_done()
    states = page.driver.execute_script(
        "return [...document.querySelectorAll('#verdict figure img')].map(i => i.dataset.state)"
    )
    # no threshold curves above the critical torque, and the note says why
    assert states == ["shown", "failed"]
    assert "above the critical torque 9.62 N·m" in page.text("#threshold-note")
    page.show("#verdict")
    page.screenshot("explorer-verdict.png", height=1150)
    page.assert_same_origin()


def test_a_gear_train_shows_its_modes_and_campbell_diagram(page: Page) -> None:
    """Issue 32: the example train inserted into the form; the analysis is the train's, and the
    page shows its modes (the mesh mode marked) and its Campbell diagram."""
    page.open()
    page.type("settings.transient_periods", "100")
    page.type("settings.record_periods", "50")
    page.field("train-example", by="id").click()
    assert '"input_shaft"' in page.field("train", by="id").get_attribute("value")
    page.field("analyse", by="id").click()
    table = page.wait(lambda d: page.text("#modes-table"))
    for hz in ("298.5", "652.6", "1100.3", "1722.5", "2799.9"):
        assert hz in table
    assert "5 (mesh mode)" in table and "56.5 %" in table
    assert "stiff limit 739.3 Hz" in page.text("#modes-note")
    page.wait(lambda d: page.field("campbell-figure", by="id").get_attribute("data-state")
              in ("shown", "failed"))  # fmt: skip
    assert page.field("campbell-figure", by="id").get_attribute("data-state") == "shown"
    assert "a gear train" in page.text("#threshold-note")
    page.figures_done()  # the train's response figure shown; no threshold curves for a train
    states = page.driver.execute_script(
        "return [...document.querySelectorAll('#verdict figure img')].map(i => i.dataset.state)"
    )
    assert states == ["shown", "failed"]
    page.show("#modes")
    page.screenshot("explorer-train.png", height=1400)
    page.assert_same_origin()


def test_a_wrong_unit_is_shown_next_to_its_field(page: Page) -> None:
    page.open()
    page.type("design.mesh.half_backlash", "100 m")
    page.field("analyse", by="id").click()
    note = page.wait(lambda d: page.text("label:has(> [data-path='design.mesh.half_backlash'])"
                                         " .field-error"))  # fmt: skip
    assert "did you mean 100 µm?" in note
    assert "invalid" in page.field("design.mesh.half_backlash").get_attribute("class")
    assert page.driver.find_element("id", "verdict").get_attribute("hidden") is not None
    assert "design.mesh.half_backlash: 100 m is outside" in page.text("#refused")
    page.screenshot("explorer-field-error.png")
    page.assert_same_origin()


def test_an_envelope_runs_on_the_queue_and_opens_a_point(page: Page) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    page.open()
    small = {
        "envelope.axes[0].start": "1000 rpm",
        "envelope.axes[0].stop": "4000 rpm",
        "envelope.axes[0].num": "7",
        "envelope.axes[1].start": "20 N*m",
        "envelope.axes[1].stop": "120 N*m",
        "envelope.axes[1].num": "3",
        "envelope.settings.transient_periods": "30",
        "envelope.settings.record_periods": "30",
    }
    screenshots = bool(os.environ.get("GEARCHAOS_EXPLORER_SCREENSHOTS"))
    if not screenshots:  # the screenshot shows the form's own envelope, 21 x 5 points
        for path, value in small.items():
            page.type(path, value)
    n = 105 if screenshots else 21
    page.field("map-range", by="id").click()
    progress = page.wait(lambda d: re.search(rf"\d+ / {n} points", page.text("#envelope")))
    assert progress
    page.wait(lambda d: page.text("#envelope-status") == "succeeded")
    points = page.wait(
        lambda d: d.find_elements(By.CSS_SELECTOR, "#envelope-map .scatterlayer path.point")
    )
    assert len(points) == n
    assert page.driver.find_elements(By.CSS_SELECTOR, "#envelope-map .contourlayer path")
    assert ("500 rpm–6000 rpm" if screenshots else "1000 rpm–4000 rpm") in page.text("#recent-jobs")
    stored = page.driver.execute_script("return localStorage.getItem('gearchaos.jobs')")
    assert json.loads(stored)[0]["status"] == "succeeded"

    # hover shows speed, torque, class, period and LLE
    point = points[len(points) // 2 + 1]
    ActionChains(page.driver).move_to_element(point).perform()
    hover = page.wait(lambda d: page.text("#envelope-map .hoverlayer"))
    for word in ("rpm", "N·m", "class", "period", "LLE"):
        assert word in hover
    page.show("#envelope")
    page.screenshot("explorer-envelope.png", height=1000)

    # clicking a point analyses the design at that speed and torque
    ActionChains(page.driver).move_to_element(point).click().perform()
    page.wait(lambda d: page.text("#verdict-summary"))
    speed = page.field("design.speed").get_attribute("value")
    torque = page.field("design.torque").get_attribute("value")
    assert speed.endswith(" rpm") and torque.endswith(" N*m")
    assert f"At {float(speed.split()[0]):,.0f} rpm" in page.text("#verdict-summary")
    assert page.field("settings.record_periods").get_attribute("value") == (
        "100" if screenshots else "30"
    )
    page.figures_done()
    page.assert_same_origin()
    assert any(u.endswith("/static/plotly.min.js") for u in page.urls)


def test_an_envelope_can_be_cancelled(page: Page) -> None:
    page.open()
    page.type("envelope.axes[0].num", "40")
    page.type("envelope.settings.transient_periods", "3000")
    page.field("map-range", by="id").click()
    page.wait(lambda d: page.text("#envelope-status") in ("queued", "running"))
    page.field("cancel-sweep", by="id").click()
    page.wait(lambda d: page.text("#envelope-status") == "cancelled")
    assert not page.field("cancel-sweep", by="id").is_displayed()
    page.assert_same_origin()


def test_a_chaotic_envelope_offers_how_do_i_fix_it(page: Page) -> None:
    """The rattling pair of examples/envelope-map.json over its chaotic band: the envelope
    offers remedies (POST /v1/remedies), and shows the answer and a map at each remedy."""
    from selenium.webdriver.common.by import By

    page.open()
    rattling = {
        "design.mesh.half_backlash": "10 um",
        "design.transmission_error.harmonics[0].amplitude": "10 um",
        "design.torque_fluctuation.harmonics[0].amplitude": "0.5 N*m",
        "envelope.axes[0].start": "4500 rpm",
        "envelope.axes[0].stop": "5000 rpm",
        "envelope.axes[0].num": "2",
        "envelope.axes[1].start": "2 N*m",
        "envelope.axes[1].stop": "11.5 N*m",
        "envelope.axes[1].num": "2",
        "envelope.settings.transient_periods": "60",
        "envelope.settings.record_periods": "60",
    }
    for path, value in rattling.items():
        page.type(path, value)
    page.field("map-range", by="id").click()
    page.wait(lambda d: page.text("#envelope-status") == "succeeded")
    fix = page.wait(lambda d: page.field("fix-it", by="id").is_displayed() and
                    page.field("fix-it", by="id"))  # fmt: skip
    fix.click()
    answer = page.wait(lambda d: page.text("#fix-answer"), timeout=900)
    assert "(numerically)" in answer and "transmission error" in answer, answer
    maps = page.wait(lambda d: d.find_elements(By.CSS_SELECTOR, "#fix-maps .scatterlayer"))
    assert len(maps) == len(page.driver.find_elements(By.CSS_SELECTOR, "#fix-maps figure"))
    assert "the envelope passes" in page.text("#fix-maps")
    page.show("#fix")
    page.screenshot("explorer-remedies.png", height=1400)
    page.assert_same_origin()


def test_without_the_key_the_page_says_so(page: Page) -> None:
    page.open(key=None)
    page.field("analyse", by="id").click()
    problem = page.wait(lambda d: page.text("#form-problem"))
    assert "API key" in problem
    assert page.driver.find_element("id", "verdict").get_attribute("hidden") is not None
    page.field("api-key", by="id").send_keys(KEY)
    page.field("analyse", by="id").click()
    page.wait(lambda d: page.text("#verdict-summary"))
    key = page.driver.execute_script("return sessionStorage.getItem('gearchaos.apiKey')")
    assert key == KEY
    page.assert_same_origin()


def test_advanced_mode_sends_dimensionless_params(page: Page) -> None:
    page.open()
    page.field("advanced", by="id").click()
    params = json.loads(page.field("params").get_attribute("value"))
    assert params["damping"] == 0.07  # the paper's section 4.1 design
    page.type("params", json.dumps({**params, "damping": -1}))
    page.field("analyse", by="id").click()
    note = page.wait(lambda d: page.text("label:has(> [data-path='params']) .field-error"))
    assert note.startswith("params.damping:")
    page.type("params", json.dumps(params))
    page.field("analyse", by="id").click()
    summary = page.wait(lambda d: page.text("#verdict-summary"))
    assert summary.startswith("numerics:") and "Melnikov: chaos possible" in summary
    page.figures_done()
    page.assert_same_origin()


def test_the_geometry_form_derives_the_gears(page: Page) -> None:
    page.open()
    assert not page.field("design.driver.module").is_displayed()
    page.driver.find_element("css selector", "input[name=form-mode][value=geometry]").click()
    assert page.field("design.driver.module").get_attribute("value") == "3 mm"
    assert page.field("design.mesh.stiffness").get_attribute("value") == "iso6336"
    assert not page.field("design.driver.base_radius").is_displayed()
    page.field("analyse", by="id").click()
    page.wait(lambda d: page.text("#verdict-summary"))
    assert "Dynamic factor" in page.text("#verdict-facts")
    page.assert_same_origin()


def test_a_probability_map_runs_on_the_queue_and_can_be_cancelled(page: Page) -> None:
    """The tolerances form: an ISO class needs the geometry form (the 422 says so); in the
    geometry form a small study shows its progress and draws the map; a long one is cancelled."""
    from selenium.webdriver.common.by import By

    page.open()
    small = {
        "envelope.axes[0].num": "3",
        "envelope.axes[1].num": "2",
        "envelope.settings.transient_periods": "30",
        "envelope.settings.record_periods": "30",
        "robustness.samples": "4",
    }
    for path, value in small.items():
        page.type(path, value)
    page.field("study-range", by="id").click()  # direct form: no module for the class
    page.wait(lambda d: "tolerances.accuracy" in page.text("#robustness-problem"))
    page.driver.find_element("css selector", "input[name=form-mode][value=geometry]").click()
    page.field("study-range", by="id").click()
    page.wait(lambda d: re.search(r"\d+ / 24 runs", page.text("#robustness")))
    page.wait(lambda d: page.text("#robustness-status") == "succeeded")
    page.wait(lambda d: d.find_elements(By.CSS_SELECTOR, "#robustness-map .heatmaplayer, "
                                        "#robustness-map .hm"))  # fmt: skip
    page.show("#robustness")
    page.screenshot("explorer-robustness.png", height=900)
    page.type("envelope.settings.transient_periods", "3000")
    page.type("robustness.samples", "64")
    page.field("study-range", by="id").click()
    page.wait(lambda d: page.text("#robustness-status") in ("queued", "running"))
    page.field("cancel-study", by="id").click()
    page.wait(lambda d: page.text("#robustness-status") == "cancelled")
    page.assert_same_origin()


def test_a_design_page_speaks_gear_units_and_enlarges_figures(page: Page) -> None:
    """Issue 26, item 11: the LLE per s as in the figure, threshold curves over the speed in
    µm, a figure opens at full size, and switching forms drops the other form's refusal."""
    page.open()
    page.field("analyse", by="id").click()
    page.wait(lambda d: page.text("#verdict-summary"))
    lle = page.text("#verdict-facts").split("Largest Lyapunov exponent")[1].splitlines()[1]
    assert " per s (" in lle and "per unit τ)" in lle
    page.figures_done()  # the threshold figure's gear units: tests/test_threshold_units.py
    page.field("analysis-figure", by="id").click()
    page.wait(lambda d: d.execute_script("return document.getElementById('enlarged').open"))
    width = page.driver.execute_script("return document.getElementById('enlarged-img').width")
    thumb = page.driver.execute_script("return document.getElementById('analysis-figure').width")
    assert width > thumb
    page.show("#verdict")
    page.screenshot("explorer-enlarged.png", height=1000)
    page.field("enlarged", by="id").click()
    page.wait(lambda d: not d.execute_script("return document.getElementById('enlarged').open"))

    page.type("design.mesh.half_backlash", "100 m")
    page.field("analyse", by="id").click()
    page.wait(lambda d: page.text("#refused"))
    page.driver.find_element("css selector", "input[name=form-mode][value=geometry]").click()
    assert not page.driver.find_elements("css selector", "#design-form .field-error")
    assert page.driver.find_element("id", "refused").get_attribute("hidden") is not None
    page.assert_same_origin()


def test_the_map_shows_impacts_and_the_dynamic_factor(page: Page) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By

    page.open()
    for path, value in {"envelope.axes[0].start": "1000 rpm", "envelope.axes[0].stop": "4000 rpm",
                        "envelope.axes[0].num": "4", "envelope.axes[1].num": "2",
                        "envelope.settings.transient_periods": "30",
                        "envelope.settings.record_periods": "30"}.items():  # fmt: skip
        page.type(path, value)
    page.field("map-range", by="id").click()
    page.wait(lambda d: page.text("#envelope-status") == "succeeded")
    points = page.wait(
        lambda d: d.find_elements(By.CSS_SELECTOR, "#envelope-map .scatterlayer path.point")
    )
    legend = page.text("#envelope-map .legend")
    assert "teeth always in contact" in legend and "back-flank impacts" in legend
    ActionChains(page.driver).move_to_element(points[0]).perform()
    hover = page.wait(lambda d: page.text("#envelope-map .hoverlayer"))
    assert "dynamic factor" in hover and "DTE" in hover and "µm" in hover
    assert "no-impact" not in hover and "impacts no" not in hover
    page.show("#envelope")
    page.screenshot("explorer-envelope-impacts.png", height=1000)


def test_basins_show_the_attractors_and_their_picture(page: Page) -> None:
    page.open()
    page.type("settings.basins.starts", "16")
    page.field("analyse", by="id").click()  # 500 + 500 periods from 16 starts: over the budget
    page.wait(lambda d: "settings.basins.starts" in page.text("#refused"))
    page.type("settings.transient_periods", "30")
    page.type("settings.record_periods", "30")
    page.field("analyse", by="id").click()
    table = page.wait(lambda d: page.text("#attractors-table"))
    assert "95 % interval" in table and "periodic" in table
    assert "16 starts" in page.text("#basins-count")
    page.figures_done()
    page.wait(lambda d: page.field("basins-figure", by="id").get_attribute("data-state") == "shown")
    page.show("#basins")
    page.screenshot("explorer-basins.png", height=1400)
    page.assert_same_origin()


def test_a_measured_signal_is_read_with_its_verdict_and_pictures(
    page: Page, tmp_path: Path
) -> None:
    """The signal view: pasted samples too short for the embedding are refused at the box; the
    project's chaotic gear response (F_e = 0.25, 25 dB of sensor noise) loaded as a CSV whose
    time column sets the rate is read as chaotic, with its evidence, summary and figure."""
    from tests.test_signals_gear import RATE, TEETH, recording

    page.open()
    page.type("signal.values", "0.1\n0.3\n0.2")
    page.field("read-signal", by="id").click()
    note = page.wait(lambda d: page.text("label:has(> [data-path='signal.values']) .field-error"))
    assert note.startswith("signal.values:") and "512" in note
    assert page.driver.find_element("id", "reading").get_attribute("hidden") is not None

    x, mesh_hz, _, _ = recording(0.25, 25.0)
    csv = tmp_path / "rig.csv"
    times = [f"{k / RATE:.8f},{v:.8g}" for k, v in enumerate(x)]
    csv.write_text("time_s,displacement_um\n" + "\n".join(times) + "\n")
    page.field("signal-file", by="id").send_keys(str(csv))
    page.wait(lambda d: f"{x.size + 1:,} lines" in page.text("#signal-file-note"))
    page.field("signal.sample_rate").clear()  # the time column sets it
    page.type("speed", f"{mesh_hz * 60.0 / TEETH:.6g} rpm")
    page.type("teeth", str(TEETH))
    page.driver.find_element(
        "css selector", "[data-path='signal.quantity'] [value=displacement]"
    ).click()
    page.field("read-signal", by="id").click()
    summary = page.wait(lambda d: page.text("#reading-summary"), timeout=300)
    assert page.text("#reading-verdict") == "chaotic", summary
    assert summary.startswith("Chaotic:") and "IAAFT surrogates" in summary
    evidence = page.text("#reading-evidence")
    assert "0-1" in evidence or "K =" in evidence, evidence
    facts = page.text("#reading-facts")
    for label in ("Record", "Shaft", "0-1 test K", "Largest Lyapunov exponent", "Surrogate test"):
        assert label in facts, facts
    assert f"{x.size:,} samples at 20,000 Hz" in facts
    page.wait(
        lambda d: page.field("signal-figure", by="id").get_attribute("data-state") == "shown",
        timeout=300,
    )
    width = page.driver.execute_script(
        "return document.getElementById('signal-figure').naturalWidth"
    )
    assert width > 600
    # the form on the left beside the results, which stay in view (sticky)
    page.driver.set_window_size(page.driver.get_window_size()["width"], 1400)
    page.driver.execute_script("document.getElementById('signal-form').scrollIntoView()")
    page.screenshot("explorer-signal.png")
    page.field("signal-figure", by="id").click()  # at full size, as the design's figures
    page.wait(lambda d: d.execute_script("return document.getElementById('enlarged').open"))
    page.field("enlarged", by="id").click()
    page.assert_same_origin()
