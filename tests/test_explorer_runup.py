"""The explorer's run-up view (issue 30 item 9): the "Run-up" form sends the design through a
speed ramp on the queue (POST /v1/runups), shows its progress, where the response is chaotic,
separates or jumps per direction, and the server's run-up figure; a bad ramp is refused beside
the form. Driven in Chromium as tests/test_explorer.py does (its server and page)."""

from __future__ import annotations

from fastapi.testclient import TestClient

from service.core.config import Settings
from service.main import create_app
from tests.test_explorer import Page, keyed_server, page  # noqa: F401 (fixtures)


def test_the_page_loads_the_runup_view(tmp_path) -> None:
    with TestClient(create_app(Settings(data_dir=tmp_path, workers=0, api_keys=""))) as client:
        script = client.get("/explorer/runup.js")
        assert script.status_code == 200
        assert script.headers["content-type"].startswith("text/javascript")
        assert "/v1/runups" in script.text
        html = client.get("/").text
        assert '<script src="/explorer/runup.js" defer></script>' in html
        assert 'id="runup-form"' in html and 'id="runup-figure"' in html


def test_a_runup_runs_on_the_queue_and_shows_its_figure(page: Page) -> None:  # noqa: F811
    page.open()
    page.type("runup.rate", "-5 rpm/s")
    page.field("start-runup", by="id").click()
    page.wait(lambda d: "rate" in page.text("#runup-problem"))
    page.type("runup.rate", "2000 rpm/s")
    page.type("runup.to_speed", "3000 rpm")
    page.field("start-runup", by="id").click()
    page.wait(lambda d: page.text("#runup-status") == "succeeded", timeout=300)
    page.wait(lambda d: d.execute_script(
        "return document.getElementById('runup-figure').dataset.state === 'shown'"))  # fmt: skip
    summary = page.text("#runup-summary")
    # the README's pair at 40 N*m stays periodic and in contact from 1,000 to 3,000 rpm
    assert "run-up: never chaotic; teeth always in contact; no jumps (20 bins of 100 rpm)" in (
        summary
    )
    assert "Melnikov windows" in summary
    width = page.driver.execute_script(
        "return document.getElementById('runup-figure').naturalWidth"
    )
    assert width > 300
    page.show("#runup")
    page.screenshot("explorer-runup.png", height=1100)
    page.assert_same_origin()
