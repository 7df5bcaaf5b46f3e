"""fleet.html: fleet.json for people, one self-contained page (inline CSS and SVG, nothing fetched)."""

from __future__ import annotations

import html
import math

_STYLE = """
body{font:14px/1.4 sans-serif;margin:24px;max-width:1100px;color:#222}
h1{font-size:22px}h2{font-size:18px;margin-top:28px}h3{font-size:15px;margin:18px 0 6px}
table{border-collapse:collapse;margin:8px 0}td,th{border:1px solid #ccc;padding:3px 8px;text-align:left}
th{background:#f3f3f3}.trusted{color:#1a7f37}.untrusted{color:#b35900}.failed,.moved{color:#c62828;font-weight:bold}
.note{color:#555}svg{background:#fff;border:1px solid #ddd}
"""


def _cell(value) -> str:
    if value is None:
        return "<td>-</td>"
    if isinstance(value, float):
        return f"<td>{value:.3g}</td>"
    return f"<td>{html.escape(str(value))}</td>"


def _table(header: list[str], rows: list[list[str]]) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in header)
    return f"<table><tr>{head}</tr>" + "".join(f"<tr>{''.join(row)}</tr>" for row in rows) + "</table>"


def _verdict_cell(verdict: str) -> str:
    return f'<td class="{html.escape(verdict)}">{html.escape(verdict)}</td>'


def _summary(fleet: dict) -> str:
    words = [f"{len(fleet['jobs'])} jobs on {len(fleet['recordings'])} recordings, {fleet['workers']} Dask worker(s), "
             f"{fleet['seconds']:.1f} s."]
    if fleet["failed_jobs"]:
        words.append(f'<span class="failed">{len(fleet["failed_jobs"])} failed</span>: {html.escape(", ".join(fleet["failed_jobs"]))}.')
    if fleet["untrusted_jobs"]:
        words.append(f'<span class="untrusted">{len(fleet["untrusted_jobs"])} not to be trusted</span> (their report says why): '
                     f'{html.escape(", ".join(fleet["untrusted_jobs"]))}.')
    for m in fleet["moved"]:
        words.append(f'<span class="moved">{html.escape(m["vehicle"])}: LiDAR {html.escape(m["lidar"])} moved</span> between '
                     f'{html.escape(m["from"])} and {html.escape(m["to"])}: {m["rotation_deg"]:.2f}°, '
                     f'{m["translation_m"] * 100:.1f} cm. Recalibrate it before trusting its data.')
    if not fleet["moved"]:
        words.append("No LiDAR moved between recordings (rule: a change beyond "
                     f"{fleet['drift_rule']['rotation_deg']}° or {fleet['drift_rule']['translation_m'] * 100:.0f} cm that "
                     "the estimates' covariances cannot explain).")
    return "<p>" + "</p><p>".join(words) + "</p>"


def _recordings(fleet: dict) -> str:
    rows = []
    for r in fleet["recordings"]:
        links = ", ".join(f'<a href="jobs/{html.escape(j)}/{page}">{html.escape(j)}</a>' for j, page in zip(r["jobs"], r["pages"]))
        rows.append([_cell(r["vehicle"]), _cell(r["recording"]), _cell(r["date"] or None), _verdict_cell(r["verdict"]),
                     f"<td>{links}</td>"])
    return _table(["vehicle", "recording", "date", "verdict", "jobs"], rows)


def _jobs(fleet: dict) -> str:
    rows = []
    for j in fleet["jobs"]:
        detail = (j.get("error") or {}).get("message") if j["status"] != "done" else (
            f"ATE {j['ate_rmse_m']:.3f} m" if j.get("ate_rmse_m") is not None else "")
        rows.append([_cell(j["id"]), _cell(j["task"]), _verdict_cell(j["verdict"]), _cell(j["exit_code"]),
                     _cell(j["seconds"]), _cell(j["starts"]), _cell(j["runs"]), _cell("yes" if j["reused"] else "no"),
                     _cell(j["worker"]), _cell(detail or None)])
    return _table(["job", "task", "verdict", "exit", "seconds", "starts", "runs", "reused", "worker", "detail"], rows)


def _chart(estimates: list[dict], key: str, sigma_key: str, scale: float, unit: str) -> str:
    """One point per recording (its change from the first) with a ±2σ bar; equal spacing along x."""
    width, height, left, bottom = 420, 170, 48, 26
    values = [e[key] * scale for e in estimates]
    bars = [2.0 * math.sqrt(sum(s * s for s in e[sigma_key])) * scale for e in estimates]
    top = max([v + b for v, b in zip(values, bars)] + [1e-9]) * 1.15
    step = (width - left - 20) / max(len(values) - 1, 1)
    y = lambda v: height - bottom - (height - bottom - 10) * v / top
    parts = [f'<line x1="{left}" y1="{y(0):.1f}" x2="{width - 10}" y2="{y(0):.1f}" stroke="#999"/>',
             f'<text x="4" y="14" font-size="11">{top:.3g} {unit}</text>',
             f'<text x="4" y="{y(0):.1f}" font-size="11">0</text>']
    for i, (value, bar, estimate) in enumerate(zip(values, bars, estimates)):
        x = left + i * step
        parts.append(f'<line x1="{x:.1f}" y1="{y(max(value - bar, 0)):.1f}" x2="{x:.1f}" y2="{y(value + bar):.1f}" stroke="#1f77b4"/>')
        parts.append(f'<circle cx="{x:.1f}" cy="{y(value):.1f}" r="3.5" fill="#1f77b4"><title>{html.escape(estimate["recording"])}: '
                     f'{value:.3g} {unit}</title></circle>')
        parts.append(f'<text x="{x:.1f}" y="{height - 8}" font-size="10" text-anchor="middle">{html.escape(estimate["recording"][:14])}</text>')
    return f'<svg width="{width}" height="{height}" role="img">{"".join(parts)}</svg>'


def _drift(fleet: dict) -> str:
    blocks = []
    for vehicle, lidars in fleet["drift"].items():
        for lidar, series in lidars.items():
            state = '<span class="moved">moved</span>' if series["moved"] else "unchanged"
            blocks.append(f"<h3>{html.escape(vehicle)} / {html.escape(lidar)}: {state}</h3>")
            blocks.append('<p class="note">Change of the extrinsic from the first recording, ±2σ of each estimate.</p>')
            blocks.append(_chart(series["estimates"], "rotation_from_first_deg", "sigma_rotation_deg", 1.0, "°") + " " +
                          _chart(series["estimates"], "translation_from_first_m", "sigma_translation_m", 100.0, "cm"))
            rows = [[_cell(c["from"]), _cell(c["to"]), _cell(c["rotation_deg"]), _cell(c["translation_m"] * 100),
                     _cell(c["d2"]), _cell({True: "yes", False: "no", None: "-"}[c["significant"]]),
                     f'<td class="{"moved" if c["moved"] else ""}">{"yes" if c["moved"] else "no"}</td>'] for c in series["changes"]]
            blocks.append(_table(["from", "to", "rotation °", "translation cm", "d²", "significant", "moved"], rows))
    return "".join(blocks) or "<p>No recording had an extrinsic estimate (calibrate-auto, or slam with online calibration).</p>"


def fleet_html(fleet: dict) -> str:
    command = html.escape(" ".join(fleet["arguments"]))
    return (f"<!DOCTYPE html><html lang=en><head><meta charset=utf-8><title>mlidar fleet</title><style>{_STYLE}</style>"
            f"</head><body><h1>mlidar fleet run</h1><p class=note>{command}<br>{html.escape(fleet['finished_utc'])}, "
            f"mlidar {html.escape(fleet['version'])}</p><h2>Summary</h2>{_summary(fleet)}<h2>Has a LiDAR moved?</h2>"
            f"{_drift(fleet)}<h2>Recordings</h2>{_recordings(fleet)}<h2>Jobs</h2>{_jobs(fleet)}</body></html>\n")
