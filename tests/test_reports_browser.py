"""Reports checked where people read them: every committed report and a fresh one, in headless Chromium.

Each page: every image loads, no console or page error, the verdict box is there, each requirement's bound is
drawn on its figure (the figure's ``data-bounds``, read back from the artists drawn), every number tagged with a
``result.json`` pointer shows that number, every number in the verdict and the tables is such a tagged number
(or says which plant it is on), and no unit is printed empty.

Needs playwright (``pip install -e .[test]``) and a Chromium binary (Debian: ``apt-get install chromium`` or
``chromium-headless-shell``; or set ``SYNTH_CHROMIUM``); playwright's own browser download is not used.
"""

from __future__ import annotations

import io
import json
import os
import re
import shutil
from contextlib import redirect_stdout
from pathlib import Path

import pytest

from synth.requirements.base import fmt

ROOT = Path(__file__).resolve().parent.parent
COMMITTED = sorted(p.relative_to(ROOT) for p in [*ROOT.glob("reports/**/report.html"),
                                                  *ROOT.glob("reports/**/tradeoff.html")])
CANDIDATES = ["/usr/lib/chromium/chromium", "chromium-headless-shell", "chromium", "chromium-browser",
              "google-chrome"]
FIGURE_OF = {"sensitivity": "sensitivity", "sensitivity_static": "sensitivity", "peak_sensitivity": "sensitivity",
             "slew_rate": "bode", "step_response": "step"}
"""Requirement type -> the figure (by its ``alt`` text start) that must draw its bound."""
ALT = {"sensitivity": "sensitivity", "bode": "Bode magnitude", "step": "step responses"}


def _chromium() -> str | None:
    for name in [os.environ.get("SYNTH_CHROMIUM", ""), *CANDIDATES]:
        found = shutil.which(name) if name else None
        if found:
            return found
    return None


def _skip_reason() -> str | None:
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return "playwright is not installed (pip install -e .[test])"
    if _chromium() is None:
        return "no Chromium found (apt-get install chromium, or set SYNTH_CHROMIUM)"
    return None


pytestmark = pytest.mark.skipif(_skip_reason() is not None, reason=_skip_reason() or "")

SPEC_WITHOUT_UNITS = """name: nounits
description: "A plant without units"
plant: {tf: "23*(s+0.43)/((s+9.6)*(s+0.54))"}
controller: {type: P, bounds: {kp: [0.1, 20]}}
requirements:
  - {type: sensitivity_static, max_db: -15, plant_gain: 1.8}
  - {type: sensitivity, max_db: -10, band: [0, 5]}
  - {type: peak_sensitivity, max_db: 6}
  - {type: bandwidth, min: 60}
  - {type: slew_rate, rate_limit: 10000, max_error: 5, band: [0.1, 100]}
objective: {maximize: bandwidth}
reference: {source: "a test", controller: "P(3)"}
"""

INSPECT = """() => {
  const tables = ['requirements', 'closed-loop', 'gain-set', 'points']
    .map(id => document.getElementById(id)).filter(t => t);
  const untagged = [];
  for (const t of tables) {
    for (const cell of t.querySelectorAll('td.num')) {
      const copy = cell.cloneNode(true);
      copy.querySelectorAll('[data-json], .plant').forEach(e => e.remove());
      if (/[0-9]/.test(copy.textContent)) untagged.push(t.id + ': ' + cell.textContent.trim());
    }
  }
  const verdict = document.querySelector('.verdict');
  return {
    images: Array.from(document.images).map(i => ({
      src: i.getAttribute('src'), alt: i.alt, ok: i.complete && i.naturalWidth > 0,
      bounds: i.dataset.bounds === undefined ? null : JSON.parse(i.dataset.bounds)})),
    verdict: verdict ? verdict.innerText : null,
    tagged: Array.from(document.querySelectorAll('[data-json]')).map(e => ({ptr: e.dataset.json, digits: e.dataset.digits,
                                                                           text: e.textContent})),
    plants: Array.from(document.querySelectorAll('#requirements td[data-plant]')).map(e => ({plant: e.dataset.plant,
                                                                                            text: e.innerText})),
    untagged: untagged,
    text: document.body.innerText,
  };
}"""


@pytest.fixture(scope="module")
def browser():
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=_chromium(), args=["--no-sandbox", "--disable-gpu"])
        yield b
        b.close()


@pytest.fixture(scope="module")
def fresh(tmp_path_factory) -> Path:
    from synth.cli import main

    root = tmp_path_factory.mktemp("fresh")
    (root / "nounits.yaml").write_text(SPEC_WITHOUT_UNITS)
    with redirect_stdout(io.StringIO()):
        assert main(["design", str(root / "nounits.yaml"), "--out", str(root / "report"), "--quiet"]) == 0
    return root / "report" / "report.html"


def _open(browser, path: Path) -> tuple[dict, list[str]]:
    page = browser.new_page()
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda e: errors.append(f"page error: {e}"))
    page.on("requestfailed", lambda r: errors.append(f"request failed: {r.url}"))
    page.goto(path.resolve().as_uri(), wait_until="load")
    info = page.evaluate(INSPECT)
    page.close()
    return info, errors


def _pointer(data: object, ptr: str) -> object:
    for key in ptr.strip("/").split("/"):
        key = key.replace("~1", "/").replace("~0", "~")
        data = data[int(key)] if isinstance(data, list) else data[key]  # type: ignore[index]
    return data


def _check_page(browser, path: Path) -> dict:
    info, errors = _open(browser, path)
    assert not errors, errors
    assert info["images"], "no figure on the page"
    bad = [i["src"] for i in info["images"] if not i["ok"]]
    assert not bad, f"images that do not load: {bad}"
    assert info["verdict"], "no verdict box"
    data = json.loads((path.parent / ("tradeoff.json" if path.name == "tradeoff.html" else "result.json")).read_text())
    assert info["tagged"], "no number is tagged with its result.json pointer"
    for t in info["tagged"]:
        value = _pointer(data, t["ptr"])
        if t["digits"] is None:  # text carried verbatim (verdict, messages, pole strings)
            assert t["text"] == str(value), t
        else:
            shown = fmt(None if value is None else float(value), int(t["digits"]))  # type: ignore[arg-type]
            assert t["text"] == shown, f"{t['ptr']}: page shows {t['text']}, result.json has {value}"
    assert not info["untagged"], f"numbers not traced to result.json: {info['untagged']}"
    for unit_gap in ("[]", " /,", " /\n"):
        assert unit_gap not in info["text"], f"an empty unit printed as {unit_gap!r}"
    if path.name == "report.html":
        _check_design_page(info, data)
    return info


def _check_design_page(info: dict, data: dict) -> None:
    assert data["verdict"] in info["verdict"]
    shown = data.get("requirements") or (data.get("compromise") or {}).get("requirements") or []
    figures = {k: next((i for i in info["images"] if i["alt"].startswith(alt)), None) for k, alt in ALT.items()}
    for req in shown:
        figure = FIGURE_OF.get(req["type"])
        if figure is None:
            continue
        img = figures[figure]
        assert img is not None and img["bounds"] is not None, f"{req['label']}: no {figure} figure with its bounds"
        drawn = [b for b in img["bounds"] if b["requirement"] == req["label"]]
        assert drawn, f"{req['label']}: bound not drawn on the {figure} figure ({img['bounds']})"
        if req["type"] == "step_response":  # the limits about the design's final value, in output units
            details = req["details"]
            if details.get("overshoot") is not None and "overshoot" in req["message"]:
                over = [b for b in drawn if b["what"].startswith("overshoot")]
                assert over and over[0]["y"][0] >= details["final_value"], drawn
        elif req["type"] != "slew_rate":  # a horizontal line at the bound, in dB
            assert drawn[0]["y"] == [pytest.approx(float(req["bound"]))] * 2, drawn
            if req["type"] == "sensitivity":
                band = req["details"]["band"]
                assert drawn[0]["x"][1] == pytest.approx(band[1], rel=1e-5), drawn
    several = len({c["plant"] for c in info["plants"]}) > 1 or any(c["plant"] != "nominal" for c in info["plants"])
    for cell in info["plants"]:
        if several:
            assert cell["plant"] in cell["text"] or "nominal" in cell["text"], cell
    if several:
        assert "on the nominal plant" in info["text"]


@pytest.mark.parametrize("report", COMMITTED, ids=str)
def test_committed_report_in_a_browser(browser, report):
    _check_page(browser, ROOT / report)


def test_fresh_report_without_units_in_a_browser(browser, fresh):
    info = _check_page(browser, fresh)
    text = info["text"]
    assert "DC gain 1.908," in text and "u \u2192 y" in text, re.findall(r"DC gain[^\n]*|input / output[^\n]*", text)
    drawn = {b["requirement"] for i in info["images"] if i["bounds"] for b in i["bounds"]}
    assert drawn == {"sensitivity_static", "sensitivity", "peak_sensitivity", "slew_rate"}


def test_the_committed_x4_report_names_the_plant_of_each_number(browser):
    info = _check_page(browser, ROOT / "reports/x4_rotor_from_data/report.html")
    data = json.loads((ROOT / "reports/x4_rotor_from_data/result.json").read_text())
    bandwidth = next(r for r in data["requirements"] if r["type"] == "bandwidth")
    assert bandwidth["plant"] != "nominal"  # the worst case is an identified variant ...
    cell = next(c for c in info["plants"] if fmt(bandwidth["value"]) in c["text"])
    assert bandwidth["plant"] in cell["text"]  # ... and the page says so beside the number
    assert f"{fmt(data['objective']['value'])} rad/s on the nominal plant" in info["text"]


STEP_SPEC = """name: pi_step
description: "A PI with an overshoot limit"
plant: {tf: "2/((s+1)*(s+2))"}
controller: {type: PI, bounds: {kp: [0.01, 5], ki: [0, 10]}}
requirements:
  - {type: step_response, max_overshoot: 10, max_settling_time: 6}
objective: {maximize: integral_gain}
"""


def test_fresh_report_with_step_limits_draws_them_in_a_browser(browser, tmp_path):
    from synth.cli import main

    (tmp_path / "step.yaml").write_text(STEP_SPEC)
    with redirect_stdout(io.StringIO()):
        assert main(["design", str(tmp_path / "step.yaml"), "--out", str(tmp_path / "report"), "--quiet"]) == 0
    info = _check_page(browser, tmp_path / "report" / "report.html")
    data = json.loads((tmp_path / "report" / "result.json").read_text())
    final = next(r for r in data["requirements"] if r["type"] == "step_response")["details"]["final_value"]
    step = next(i for i in info["images"] if i["alt"].startswith("step responses"))
    drawn = {b["what"].split(" ")[0]: b for b in step["bounds"]}
    assert drawn["overshoot"]["y"] == [pytest.approx(1.1 * final, rel=1e-5)] * 2
    assert drawn["settling"]["x"][0] == pytest.approx(6.0) and drawn["settling"]["y"] == [
        pytest.approx(0.98 * final, rel=1e-5), pytest.approx(1.02 * final, rel=1e-5)]
