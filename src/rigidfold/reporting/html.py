"""The report page of a generate run: one self-contained HTML file.

It opens with the answer (final DOF against the target, N_lock, the verdict of every check,
the final design's file), then the interactive 3D view (plotly, its JavaScript embedded),
the final design's thick panels (``generate --thickness``: a table and their 3D view along
the folding slider) and structure (``--structure``: a table and the deflected shape) where
they were made, the figures (PNG as ``data:`` URIs) and the tables of ``summary.json`` and
``log.jsonl``.
Nothing in the page is fetched: no CDN, no web font, no external image.
"""

from __future__ import annotations

import base64
import html
import math
from importlib.metadata import PackageNotFoundError, version

import numpy as np

from rigidfold.generate import Stop
from rigidfold.reporting.figures import Figure
from rigidfold.rundir import Check, RunData

CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, Arial, sans-serif;
  margin: 0 auto; max-width: 1100px; padding: 1em 1.5em 3em; color: #222; line-height: 1.4; }
h1 { font-size: 1.5em; margin-bottom: 0.1em; }
h2 { font-size: 1.2em; border-bottom: 1px solid #ddd; padding-bottom: 0.2em; margin-top: 2em; }
.sub { color: #666; margin-top: 0; }
.answer { display: flex; flex-wrap: wrap; gap: 0.8em; margin: 1em 0; }
.answer div { border: 1px solid #ddd; border-radius: 6px; padding: 0.5em 0.9em; min-width: 9em; }
.answer dt { font-size: 0.8em; color: #666; }
.answer dd { margin: 0; font-size: 1.3em; font-weight: 600; }
.verdict { font-size: 1.1em; font-weight: 600; padding: 0.5em 0.9em; border-radius: 6px; }
.ok { background: #e6f4ea; color: #1e6b34; } .bad { background: #fce8e6; color: #a50e0e; }
.none { background: #f1f3f4; color: #555; }
.passed { color: #1e6b34; } .FAILED { color: #a50e0e; } .notrun { color: #777; }
.passedbythefinaldesign { color: #8a5a00; }
.note { color: #8a5300; }
table { border-collapse: collapse; margin: 0.6em 0; font-size: 0.9em; }
th, td { border: 1px solid #ddd; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
th { background: #f6f6f6; } td { max-width: 40em; }
td.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
figure { margin: 1.2em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9em; max-width: 48em; }
.tables { display: flex; flex-wrap: wrap; gap: 0 2em; align-items: flex-start; }
.tables h3 { font-size: 1em; margin-bottom: 0.2em; }
#view3d + p { margin-top: 0.2em; }
code { background: #f4f4f4; padding: 0 0.25em; border-radius: 3px; }
"""

PLOT_CONFIG = {"displaylogo": False, "responsive": True, "scrollZoom": True}
"""plotly's options: no link to plotly's site; zoom with the wheel."""


def page(
    run: RunData,
    figures: list[Figure],
    view: dict | None,
    thick: dict | None = None,
    thick_note: str = "",
) -> str:
    """The whole HTML document of ``run`` with its ``figures`` and 3D ``view`` (a plotly
    figure dict, None when the run has no solution), and the 3D view of its thick panels
    (``thick``, None when there is none to show: ``thick_note`` says why)."""
    s = run.summary
    case = s.case
    surface = (case.get("surface") or {}).get("name", "?")
    options = s.options
    title = f"rigidfold generate: {surface} surface, pattern {case.get('pattern', '?')}"
    parts = [
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{_e(title)}</title>\n<style>{CSS}</style>\n</head>\n<body>",
        f"<h1>{_e(title)}</h1>",
        f'<p class="sub">criterion {_e(options.get("criterion", "?"))}, seed '
        f"{_e(options.get('seed', '?'))}, run directory <code>{_e(run.directory.name)}</code>"
        "</p>",
        *_answer(run),
        '<h2 id="view">Final design in 3D</h2>',
        *_view(run, view),
        *_thick(run, thick, thick_note),
        *_structure(run),
        *_drive(run),
        '<h2 id="figures">Figures</h2>',
        *(_figure(f) for f in figures),
        '<h2 id="tables">Tables</h2>',
        *_tables(run),
        f'<p class="sub">Written by rigidfold {_e(_version())} from summary.json, log.jsonl '
        "and the solution files; the figures are also in figures/.</p>",
        "</body>\n</html>\n",
    ]
    return "\n".join(parts)


def _answer(run: RunData) -> list[str]:
    s, final = run.summary, run.final
    checks = run.checks()
    failed = [c.name for c in checks if c.passed is False]
    not_run = [c.name for c in checks if c.passed is None]
    stop, target = s.stop, run.target_dof
    if final is None:
        verdict = "No solution"
    elif failed:
        verdict = "Failed: " + ", ".join(failed)
    else:
        verdict = "Every check passed" + (f" ({', '.join(not_run)} not run)" if not_run else "")
    if stop == Stop.TARGET_REACHED:
        outcome = f"target DOF {target} reached"
    elif stop == Stop.RUNNING:
        outcome = "the run has not finished: this is its state so far"
    elif stop == "interrupted":
        outcome = "the run was interrupted (Ctrl-C or SIGTERM): this is its state then"
    else:
        outcome = f"target DOF {target} not reached: {s.stop_reason}"
    # green: all done and passed; grey: passed, but a stage did not run or the run goes on
    css = (
        "bad"
        if final is None or failed or stop not in (Stop.TARGET_REACHED, Stop.RUNNING)
        else "ok"
    )
    if css == "ok" and (not_run or stop == Stop.RUNNING):
        css = "none"
    given = s.verdict  # the verdict generate judged its exit code by, when finished
    if given is not None:
        passed = given["outcome"] == "passed"
        verdict, outcome = ("Passed" if passed else "Fell short"), given["message"]
        css = "ok" if passed else "bad"
    margin = s.dof_margin or {}
    dof_text = "–" if s.final_dof is None else str(s.final_dof)
    if margin and not margin.get("clear", True):
        near = margin.get("near")
        dof_text += f" (no clear margin: {near} near-mechanism{'' if near == 1 else 's'})"
    lowest = s.lowest_dof
    items = [
        ("final DOF", dof_text),
        *((("lowest DOF reached", str(lowest)),) if lowest not in (None, s.final_dof) else ()),
        ("target DOF", "–" if target is None else str(target)),
        ("N_lock", str(s.n_lock)),
        *((("N_path", str(s.n_path)),) if s.deploy_check else ()),
        *((("N_rigid (second-order rigid)", str(s.n_rigid)),) if s.n_rigid else ()),
        *((("retracted (backtracking)", str(s.n_backtrack)),) if s.n_backtrack else ()),
        (
            "deploys",
            "–"
            if s.final_deploys is None
            else ("yes: its folding path reaches the flat state" if s.final_deploys else "no"),
        ),
        ("final design", "none" if final is None else final.name),
    ]
    out = [
        f'<p class="verdict {css}">{_e(verdict)}; {_e(outcome)}.</p>',
        '<dl class="answer">',
        *(f"<div><dt>{_e(k)}</dt><dd>{_e(v)}</dd></div>" for k, v in items),
        "</dl>",
        "<ul>",
        *(_check_item(c) for c in checks),
        "</ul>",
    ]
    if run.surface_note:
        out.append(f'<p class="note">{_e(run.surface_note)}: the fit is not shown.</p>')
    bound = run.at_dz_bound
    if bound is not None:
        out.append(
            f'<p class="note">The final design is at the dz bound: max |z - target| = '
            f"{bound * 1e3:.1f} mm = dz, as far from the target as --dz allows; a finer "
            "pattern may approximate the target more closely.</p>"
        )
    return out


def _check_item(check: Check) -> str:
    word = check.word
    return (
        f'<li><span class="{word.replace(" ", "")}"><b>{_e(check.name)}</b>: {_e(word)}</span> '
        f"— {_e(check.detail)}</li>"
    )


def _view(run: RunData, view: dict | None) -> list[str]:
    if view is None:
        return ['<p class="note">The run has no solution to show.</p>']
    import plotly.io

    final = run.final
    assert final is not None
    motion = (
        "Drag to turn, scroll to zoom; the slider below folds the sheet from flat (0%) to the "
        "design (100%), each frame placed to best fit the design."
        if view["frames"]
        else "Drag to turn, scroll to zoom. The folding motion was not traced for this design."
    )
    colour = (
        "Colour: z - target(x, y) in mm at each vertex (purple below the target, orange above), "
        "a property of the design carried along the motion; the target surface is the grey "
        "overlay."
        if run.surface is not None
        else "Colour: height z."
    )
    div = plotly.io.to_html(
        view,
        config=PLOT_CONFIG,
        auto_play=False,
        include_plotlyjs=True,
        full_html=False,
        div_id="view3d",
        default_width="100%",
        validate=False,
    )
    return [div, f"<p class='sub'>{_e(motion)} {_e(colour)}</p>"]


def _thick(run: RunData, view: dict | None, note: str) -> list[str]:
    """The thick panels' section, [] where they were not made."""
    record = run.final_record
    f = None if record is None else record.fabrication
    if f is None:
        return []
    import plotly.io

    closest = f.get("closest") or {}
    rows = {
        "verdict": f.get("message"),
        "thickness (mm)": _mm(f.get("thickness_m")),
        "side of the design surface": f.get("side"),
        "panels": f.get("panels"),
        "hinges": f.get("hinges"),
        "smallest gap (mm)": _mm(f.get("min_gap_m")),
        "closest pair": closest.get("detail"),
        "gap required (mm)": _mm(f.get("required_gap_m")),
        "hinge margin (deg)": f.get("hinge_margin_deg"),
        "trimming loss (share of area x thickness)": f.get("trimming_loss"),
        "volume (m^3)": f.get("volume_m3"),
        "mass (kg)": f.get("mass_kg"),
        "density (kg/m^3)": f.get("density_kg_m3"),
        "thinnest panel depth (mm)": _mm(f.get("thinnest_depth_m")),
        "thinner thickness that passes (mm)": _mm(f.get("passing_thickness_m")),
        "frames checked": f.get("frames_checked"),
        "motion": (f.get("motion") or {}).get("source"),
        "cut sheets (stock sheets)": f.get("cut_sheets"),
        "files": f"{len(f.get('files') or [])} in final/thick/",
    }
    out = [
        '<h2 id="thick">Thick panels</h2>',
        "<p>The final design's panels as solids (Tachi's tapered thick panels, hinge axes on "
        "the creases), checked pair by pair over the whole folding motion; their solids "
        "(GLB, STL, OBJ, 3DM), hinge and vertex schedules and nested cut sheets are in "
        "<code>final/thick/</code>.</p>",
        _pairs(rows),
    ]
    if view is None:
        out.append(f'<p class="note">{_e(note or "The thick panels cannot be shown.")}</p>')
        return out
    div = plotly.io.to_html(
        view,
        config=PLOT_CONFIG,
        auto_play=False,
        include_plotlyjs=False,  # the 3D view above embeds it
        full_html=False,
        div_id="thick3d",
        default_width="100%",
        validate=False,
    )
    pair = closest.get("panels")
    what = (
        f"panels {pair[0]} and {pair[1]} (red) come closest"
        + (
            f", at {100 * closest['fraction']:.0f}% folded"
            if closest.get("fraction") is not None
            else ""
        )
        if pair
        else "no two panels that are not neighbours come near each other"
    )
    motion = (
        "The slider folds the solids from flat (0%) to the design (100%), each moving with "
        "its panel."
        if view["frames"]
        else "The folding motion was not traced: the solids are shown in the design."
    )
    return [*out, div, f"<p class='sub'>{_e(motion)} Of every pair, {_e(what)}.</p>"]


def _drive(run: RunData) -> list[str]:
    """The deployment drive's section (``generate --deploy``), [] where it did not run."""
    record = run.final_record
    f = None if record is None else record.drive
    if f is None:
        return []
    out = [
        '<h2 id="drive">Deployment drive</h2>',
        f"<p>{_e(str(f.get('message') or ''))}</p>",
        "<p>The final design deployed from flat under its own weight by one actuator: the "
        "drive's torque along the motion (s from 0, flat, to 1, built), its dead points and "
        "the zones where a brake must hold it; the driven crease is drawn in orange in the 3D "
        "view. <code>final/deploy/deploy.json</code> holds every figure, "
        "<code>deploy.csv</code> the motor schedule.</p>",
    ]
    png = run.drive_figure()
    if png is not None:
        out.append(
            _png_figure(
                "deploy.png",
                "drive torque along the deployment",
                png,
                "<b>Deployment drive.</b> The torque of the named drive against s, dead points, "
                "sign changes and brake zones marked; the energy "
                "(<code>final/deploy/deploy.png</code>).",
            )
        )
    return out


def _structure(run: RunData) -> list[str]:
    """The structure section, [] where the structure was not checked."""
    record = run.final_record
    f = None if record is None else record.structure
    if f is None:
        return []
    supports = f.get("supports") or {}
    service = supports.get("service")
    added = (
        {"of which for the deflection": service.get("added_for_deflection")}
        if isinstance(service, dict)
        else {}
    )
    at = f.get("max_displacement_at") or {}
    material = f.get("material") or {}
    rows = {
        "verdict": f"{f.get('status')}: {f.get('message')}",
        "material": material.get("name"),
        "E (Pa), nu, density (kg/m^3)": [
            material.get("E_Pa"),
            material.get("nu"),
            material.get("density_kg_m3"),
        ],
        "thickness (mm)": _mm(f.get("thickness_m")),
        "loads": ["self-weight"] * bool(f.get("self_weight"))
        + [_fmt(load) for load in f.get("loads") or []],
        "supports (pinned vertices)": f"{supports.get('pinned')} ({supports.get('chosen')})",
        **added,
        "first-order rigid on them": supports.get("first_order_rigid"),
        "mechanism left": supports.get("mode"),
        "total load (N)": f.get("total_load_N"),
        "reactions balance to": f.get("balance_error"),
        "largest displacement (mm)": _mm(f.get("max_displacement_m")),
        "where (nearest vertex)": at.get("nearest_vertex"),
        "allowed (mm)": _mm(f.get("allowed_displacement_m")),
        "limit, span (m)": f"{f.get('limit')}, {_fmt(f.get('span_m'))}",
        "natural frequencies (Hz)": f.get("frequencies_Hz"),
        "largest von Mises stress (MPa)": None
        if f.get("max_von_mises_Pa") is None
        else f["max_von_mises_Pa"] / 1e6,
    }
    reactions = f.get("reactions_N") or {}
    out = [
        '<h2 id="structure">Structure</h2>',
        "<p>The final design as a structure: panels as shells of the material, free creases "
        "as hinges, on its supports under its loads (OpenSees); <code>final/structure/"
        "structure.json</code> holds every figure.</p>",
        _pairs(rows),
    ]
    if reactions:
        out += [
            "<h3>Reactions</h3>",
            _grid(
                ["support (vertex)", "Fx (N)", "Fy (N)", "Fz (N)"],
                [[int(v), *force] for v, force in reactions.items()],
            ),
        ]
    png = run.structure_figure()
    if png is not None:
        out.append(
            _png_figure(
                "structure.png",
                "deflected shape",
                png,
                "<b>Deflected shape.</b> The design (grey) and its deflected shape, scaled, "
                "coloured by the displacement; the supports as red triangles "
                "(<code>final/structure/structure.png</code>).",
            )
        )
    return out


def _png_figure(name: str, alt: str, png: bytes, caption: str) -> str:
    """A ``<figure>`` of the PNG ``png`` embedded, its id ``name``, its caption (HTML)."""
    data = base64.b64encode(png).decode("ascii")
    return (
        f'<figure id="{name}"><img alt="{alt}" src="data:image/png;base64,{data}">'
        f"<figcaption>{caption}</figcaption></figure>"
    )


def _mm(metres) -> float | None:
    return (
        metres * 1e3 if isinstance(metres, int | float) and not isinstance(metres, bool) else None
    )


def _figure(figure: Figure) -> str:
    data = base64.b64encode(figure.png).decode("ascii")
    return (
        f'<figure id="{_e(figure.name)}"><img alt="{_e(figure.title)}" '
        f'src="data:image/png;base64,{data}">'
        f"<figcaption><b>{_e(figure.title)}.</b> {_e(figure.caption)} "
        f"(<code>figures/{_e(figure.name)}</code>)</figcaption></figure>"
    )


def _tables(run: RunData) -> list[str]:
    s = run.summary.to_dict()
    run_keys = (
        "stop_reason initial_dof final_dof lowest_dof n_reduce n_lock n_exceed n_path n_rigid "
        "n_backtrack "
        "deploy_check "
        "final_deploys n_solutions n_solves n_repeats n_skipped mean_f_accepted mean_f_all_solves"
    ).split()
    blocks = [("Run", _pairs({k: s[k] for k in run_keys}))]
    for key, head in (
        ("development", "Development (Step 8), all solutions"),
        ("deformation", "Large deformation (Step 9), all solutions"),
        ("motion", "Folding motion, all solutions"),
        ("time_s", "Time (s)"),
        ("options", "Options"),
        ("case", "Case"),
    ):
        if isinstance(s.get(key), dict):
            blocks.append((head, _pairs(s[key])))
    return [
        '<div class="tables">',
        *(f"<div><h3>{_e(head)}</h3>{table}</div>" for head, table in blocks),
        "</div>",
        "<h3>Solutions</h3>",
        _solutions(run),
        *_attempts(run),
    ]


def _solutions(run: RunData) -> str:
    fit = run.fit() * 1e3
    head = [
        "step",
        "DOF",
        "file",
        "development",
        "D",
        "motion",
        "large deformation",
        "max |dl| (mm)",
        "max |drho_fix| (deg)",
        "deformation vs motion",
        "max |z - target| (mm)",
        "RMS (mm)",
    ]
    rows = []
    for k, r in enumerate(run.summary.per_solution):
        dev, mot, dfm = r.development or {}, r.motion or {}, r.deformation
        name = run.names[k] if k < len(run.names) else ""
        rows.append(
            [
                r.step,
                r.dof,
                name,
                dev.get("status"),
                dev.get("D"),
                mot.get("status", "not run"),
                "not run" if not dfm else dfm.get("status"),
                None if not dfm else dfm.get("max_dl_mm"),
                None if not dfm else dfm.get("max_drho_fix_deg"),
                _agreement(r.verdicts),
                *(fit[k] if k < len(fit) else (None, None)),
            ]
        )
    return _grid(head, rows)


def _agreement(verdicts: dict | None) -> str:
    """Whether the large-deformation analysis and the folding motion agree on a solution and,
    when not, why (:class:`rigidfold.deform.Verdicts`); "not compared" when Step 9 did not
    run (or the run is of a version before the verdicts)."""
    if not verdicts:
        return "not compared"
    if verdicts.get("agreement") == "agree":
        return "agree"
    return f"differ: {verdicts.get('reason', '')}"


def _attempts(run: RunData) -> list[str]:
    head = ["attempt", "fixed added", "outcome", "DOF", "F", "iterations", "locked creases"]
    rows = [
        [
            a.index,
            a.fixed_added,
            a.outcome,
            a.dof,
            a.F,
            a.iterations,
            a.locked,
        ]
        for a in run.attempts
    ]
    return [
        f"<details><summary>Attempts ({len(rows)}, log.jsonl)</summary>",
        _grid(head, rows),
        "</details>",
    ]


def _pairs(data: dict) -> str:
    body = "".join(f"<tr><th>{_e(k)}</th><td>{_e(_fmt(v))}</td></tr>" for k, v in data.items())
    return f"<table>{body}</table>"


def _grid(head: list[str], rows: list[list]) -> str:
    top = "".join(f"<th>{_e(h)}</th>" for h in head)
    body = "".join("<tr>" + "".join(_cell(v) for v in row) + "</tr>" for row in rows)
    return f"<table><tr>{top}</tr>{body}</table>"


def _cell(value) -> str:
    numeric = isinstance(value, int | float | np.number) and not isinstance(value, bool)
    return f'<td class="n">{_e(_fmt(value))}</td>' if numeric else f"<td>{_e(_fmt(value))}</td>"


def _fmt(value) -> str:
    """A JSON value in a few words: numbers to 4 significant digits, long lists cut."""
    if value is None:
        return "–"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int | np.integer):
        return str(value)
    if isinstance(value, float | np.floating):
        return "–" if not math.isfinite(value) else f"{value:.4g}"
    if isinstance(value, dict):
        return "; ".join(f"{k}: {_fmt(v)}" for k, v in value.items())
    if isinstance(value, list | tuple):
        shown = ", ".join(_fmt(v) for v in value[:12])
        more = f", … ({len(value)} in all)" if len(value) > 12 else ""
        return f"[{shown}{more}]"
    return str(value)


def _e(value) -> str:
    return html.escape(str(value), quote=True)


def _version() -> str:
    try:
        return version("rigidfold")
    except PackageNotFoundError:
        return "(not installed)"
