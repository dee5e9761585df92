"""POST /v1/signals, its upload and plot routes, and ``gearengine signal``: bad input is a 422
naming the field (or ``undetermined`` with the reason), the CLI's --json is the API's body."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from fastapi.testclient import TestClient

from gearengine.cli.main import main
from gearengine.signals.series import MIN_SAMPLES, SYNC_SAMPLES

RATE = 20000.0


def mesh_tones(seconds: float = 1.0, rpm: float = 1500.0, teeth: int = 18) -> np.ndarray:
    """A mesh line and its second harmonic at ``rpm`` x ``teeth`` with a little noise."""
    t = np.arange(round(RATE * seconds)) / RATE
    f = rpm / 60.0 * teeth
    rng = np.random.default_rng(5)
    return (
        np.sin(2 * np.pi * f * t) + 0.3 * np.sin(4 * np.pi * f * t) + 0.02 * rng.normal(size=t.size)
    )


def body(values: np.ndarray | list[float], **extra: object) -> dict[str, object]:
    x = values.tolist() if isinstance(values, np.ndarray) else values
    signal = {"values": x, "sample_rate": "20 kHz", "quantity": "transmission_error",
              "unit": "um"}  # fmt: skip
    return {"signal": signal, "speed": "1500 rpm", "teeth": 18, **extra}


def errors(response) -> list[tuple[str, str]]:  # type: ignore[no-untyped-def]
    assert response.status_code == 422, response.text
    assert response.headers["content-type"].startswith("application/problem+json")
    return [(e["path"], e["message"]) for e in response.json()["errors"]]


def test_a_mesh_signal_is_read_in_orders(client: TestClient) -> None:
    r = client.post("/v1/signals", json=body(mesh_tones()))
    assert r.status_code == 200, r.text
    doc = r.json()
    assert doc["verdict"] == "periodic"
    assert doc["reference"]["mesh_hz"] == pytest.approx(450.0)
    assert [ln["label"] for ln in doc["spectrum"]["lines"][:2]] == [
        "mesh harmonic 1", "mesh harmonic 2"
    ]  # fmt: skip
    assert doc["spectrum"]["lines"][0]["amplitude"] == pytest.approx(1.0, rel=0.02)


def test_nan_is_refused_naming_the_sample(client: TestClient) -> None:
    x = mesh_tones().tolist()
    x[7] = math.nan
    text = json.dumps(body(x))  # NaN as JSON's extension; the service refuses it by name
    r = client.post("/v1/signals", content=text, headers={"content-type": "application/json"})
    assert [p for p, _ in errors(r)] == ["signal.values[7]"]


def test_constant_and_short_series_are_refused(client: TestClient) -> None:
    ((path, message),) = errors(client.post("/v1/signals", json=body([0.5] * 1000)))
    assert path == "signal.values" and "constant" in message
    ((path, message),) = errors(client.post("/v1/signals", json=body(mesh_tones()[:100])))
    assert path == "signal.values" and str(MIN_SAMPLES) in message


def test_sample_rate_below_twice_the_mesh_frequency_is_refused(client: TestClient) -> None:
    ((path, message),) = errors(client.post("/v1/signals", json=body(mesh_tones(), teeth=900)))
    assert path == "signal.sample_rate"
    assert "below twice the mesh frequency (22500 Hz at 1500 rpm)" in message


def test_a_speed_the_spectrum_does_not_show_is_undetermined_with_the_speed_it_shows(
    client: TestClient,
) -> None:
    r = client.post("/v1/signals", json=body(mesh_tones(), speed="1400 rpm"))
    doc = r.json()
    assert r.status_code == 200 and doc["verdict"] == "undetermined"
    assert "does not match the spectrum" in doc["summary"]
    implied = re.search(r"the mesh order 18 at ([0-9.]+) rpm", doc["summary"])
    assert implied is not None and float(implied.group(1)) == pytest.approx(1500.0, rel=1e-4)


def test_a_signal_unit_of_the_wrong_dimension_is_refused(client: TestClient) -> None:
    doc = body(mesh_tones())
    doc["signal"]["unit"] = "m/s^2"  # type: ignore[index]
    ((path, message),) = errors(client.post("/v1/signals", json=doc))
    assert path == "signal.unit" and "transmission error" in message


def test_over_the_synchronous_budget_is_refused_before_compute(client: TestClient) -> None:
    x = np.tile(mesh_tones(), math.ceil((SYNC_SAMPLES + 1) / RATE))
    r = client.post("/v1/signals", json=body(x))
    ((path, message),) = errors(r)
    assert path == "signal.values" and f"budget of {SYNC_SAMPLES} samples" in message
    assert r.json()["type"].endswith("over-budget")


def test_csv_upload_reads_the_rate_from_its_time_column(client: TestClient) -> None:
    x = mesh_tones()
    t = np.arange(x.size) / RATE
    csv = "time,te\n" + "\n".join(f"{a:.8f},{b:.10g}" for a, b in zip(t, x, strict=True))
    r = client.post("/v1/signals/upload?speed=1500rpm&teeth=18&unit=um", content=csv,
                    headers={"content-type": "text/csv"})  # fmt: skip
    assert r.status_code == 200, r.text
    assert r.json()["record"]["sample_rate_hz"] == pytest.approx(RATE, rel=1e-6)
    assert r.json()["verdict"] == "periodic"
    bad = client.post("/v1/signals/upload?rate=20kHz", content="te\n1\n2\nabc\n",
                      headers={"content-type": "text/csv"})  # fmt: skip
    assert errors(bad) == [("signal.values", "line 4: not a number: 'abc'")]


def test_cli_json_is_the_api_body_and_bad_input_exits_2(
    client: TestClient, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    doc = body(mesh_tones())
    request = tmp_path / "signal.json"
    request.write_text(json.dumps(doc))
    out = tmp_path / "out.json"
    assert main(["signal", str(request), "--json", str(out)]) == 0
    assert "verdict: periodic" in capsys.readouterr().out
    api = client.post("/v1/signals", json=doc)
    assert out.read_bytes() == api.content
    column = tmp_path / "te.txt"
    column.write_text("\n".join(str(v) for v in mesh_tones()))
    assert main(["signal", str(column), "--speed", "1500", "--teeth", "900", "--rate",
                 "20kHz"]) == 2  # fmt: skip
    assert "signal.sample_rate" in capsys.readouterr().err


def test_plot_route_and_cli_plot_draw_the_reading(client: TestClient, tmp_path: Path) -> None:
    r = client.post("/v1/signals/plot", json=body(mesh_tones(0.7)))
    assert r.status_code == 200 and r.headers["content-type"] == "image/png"
    assert r.content[:8] == b"\x89PNG\r\n\x1a\n"
    column = tmp_path / "te.txt"
    column.write_text("\n".join(str(v) for v in mesh_tones(0.7)))
    svg = tmp_path / "reading.svg"
    assert main(["signal", str(column), "--rate", "20kHz", "--plot", str(svg)]) == 0
    assert svg.read_text().lstrip().startswith("<?xml")


def test_with_a_design_the_models_verdict_stands_beside_the_signals(client: TestClient) -> None:
    from gearengine.model.design import EXAMPLE_DESIGN

    doc = body(mesh_tones())
    del doc["teeth"]  # the design's driver has 18 teeth
    r = client.post("/v1/signals", json={**doc, "design": EXAMPLE_DESIGN})
    assert r.status_code == 200, r.text
    model = r.json()["model"]
    assert model["speed_rpm"] == pytest.approx(1500.0) and model["torque_nm"] == 40.0
    assert model["classification"] == "periodic" and model["agrees"] is True
    mesh = [ln for ln in model["lines"] if ln["label"] == "mesh harmonic 1"]
    assert mesh and mesh[0]["order"] == pytest.approx(18.0, abs=1e-3)
    assert r.json()["reference"]["teeth"] == 18


def test_tach_and_teeth_are_checked(client: TestClient) -> None:
    doc = body(mesh_tones())
    del doc["speed"]
    doc["tach"] = {"times": [0.0, 0.04, 0.03, 0.08], "per_revolution": 1}
    assert errors(client.post("/v1/signals", json=doc))[0][0] == "tach.times[2]"
    del doc["tach"]
    assert errors(client.post("/v1/signals", json=doc))[0][0] == "teeth"


def test_the_upload_plot_draws_the_reading_of_the_uploaded_text(client: TestClient) -> None:
    """The explorer's figure of a pasted or loaded CSV: the same bytes as the JSON plot
    route's for the same request, answered from the reading the upload route cached; a bad
    query field is a 422 naming it."""
    x = mesh_tones(0.7)
    text = "\n".join(f"{v:.10g}" for v in x)
    query = "?rate=20kHz&speed=1500rpm&teeth=18&quantity=transmission_error&unit=um"
    headers = {"content-type": "text/csv"}
    reading = client.post("/v1/signals/upload" + query, content=text, headers=headers)
    assert reading.status_code == 200 and reading.json()["verdict"] == "periodic"
    png = client.post("/v1/signals/upload/plot" + query + "&format=png", content=text,
                      headers=headers)  # fmt: skip
    assert png.status_code == 200 and png.headers["content-type"] == "image/png"
    values = [float(v) for v in text.split()]
    same = client.post("/v1/signals/plot?format=png", json=body(values))
    assert same.status_code == 200 and same.content == png.content
    bad = client.post("/v1/signals/upload/plot?rate=20kHz&speed=fast", content=text,
                      headers=headers)  # fmt: skip
    assert [path for path, _ in errors(bad)] == ["speed"]
