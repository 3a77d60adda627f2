"""Self-contained HTML report of the IMO standard set (PNGs embedded as data URIs, no scripts)."""

from __future__ import annotations

import base64
import html
from pathlib import Path

from steerlab.trials.imo_criteria import model_scale_note
from steerlab.trials.tables import ROWS, _v, imo_rows

_CSS = """body{font-family:sans-serif;max-width:60em;margin:1em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:.5em 0 1em}td,th{border:1px solid #ccc;padding:.2em .5em;text-align:left}
.pass{color:#060;font-weight:bold}.fail{color:#a00;font-weight:bold}.na{color:#666}
img{max-width:100%;border:1px solid #ddd;margin:.3em 0}"""


def _e(x) -> str:
    return html.escape(str(x))


def _verdict(v) -> str:
    cls, text = {True: ("pass", "PASS"), False: ("fail", "FAIL"), None: ("na", "n/a")}[v]
    return f'<span class="{cls}">{text}</span>'


def _table(rows, head=("quantity", "value", "unit")) -> str:
    h = "".join(f"<th>{_e(c)}</th>" for c in head)
    body = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f"<table><tr>{h}</tr>{body}</table>"


def _img(path: Path, alt: str) -> str:
    data = base64.b64encode(Path(path).read_bytes()).decode("ascii")
    return f'<img alt="{_e(alt)}" src="data:image/png;base64,{data}">'


def write_imo_html(path: Path, report: dict, figures: dict) -> Path:
    """``report.html``: verdict, criteria table, course stability, each trial's table and figures.

    ``figures``: trial label -> list of PNG paths (embedded, so the page stands alone).
    """
    c = report["conditions"]
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>IMO trials: {_e(report['ship'])}</title>"
             f"<style>{_CSS}</style></head><body>",
             f"<h1>IMO manoeuvring trials: {_e(report['ship'])}</h1>",
             f"<p>Overall: {_verdict(report['overall_pass'])} (every applicable criterion)"
             + (f"; {_e(model_scale_note(c['model_scale']))}" if c.get("model_scale") is not None else "")
             + ".</p>",
             _table([(k, _v(v), "") for k, v in c.items()], ("condition", "value", "")),
             "<h2>Criteria</h2>"]
    rows = "".join(f"<tr><td>{_e(x['trial'])}</td><td>{_e(x['criterion'])}</td><td>{x['value']:.4g}</td>"
                   f"<td>{x['limit']:.4g}</td><td>{_e(x['unit'])}</td><td>{_verdict(x['pass'])}</td>"
                   f"<td>{_e(x['source'])}</td></tr>" if x["value"] is not None else
                   f"<tr><td>{_e(x['trial'])}</td><td>{_e(x['criterion'])}</td><td>-</td><td>{x['limit']:.4g}</td>"
                   f"<td>{_e(x['unit'])}</td><td>{_verdict(None)}</td><td>{_e(x['source'])}</td></tr>"
                   for x in report["criteria"])
    parts.append("<table><tr><th>trial</th><th>criterion</th><th>value</th><th>limit</th><th>unit</th>"
                 f"<th>verdict</th><th>source</th></tr>{rows}</table>")
    parts.append("<p>Not assessed: " + "; ".join(_e(x) for x in report["not_assessed"]) + "</p>")
    cs = report["course_stability"]
    parts.append("<h2>Course stability (information; no IMO limit)</h2>")
    parts.append(_table([(k, _v(v), "") for k, v in cs.items()], ("quantity", "value", "")))
    for label, m in report["trials"].items():
        kind = m.get("trial_kind")
        parts.append(f"<h2>{_e(label)}</h2>")
        if kind in ROWS:
            parts.append(_table(ROWS[kind](m)))
        if m.get("imo"):
            parts.append(_table(imo_rows(m["imo"]), ("criterion", "value", "source")))
        for p in figures.get(label, []):
            parts.append(_img(p, f"{label}: {Path(p).stem}"))
    parts.append(f"<p><small>{_e(report['source'])}</small></p></body></html>")
    Path(path).write_text("\n".join(parts), encoding="utf-8")
    return Path(path)
