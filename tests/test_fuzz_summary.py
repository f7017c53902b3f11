"""Fuzz test of what ``rigidfold report`` reads (issue 30, item 14): a generate run's
``summary.json`` and ``log.jsonl`` (and the rigidfold keys of its solution files) damaged, by
hand (the mutations that gave a traceback) and by a seeded mutator. Every case must end with
exit code 0, or 2 with one line ``rigidfold: error: ...`` that names the damaged file (and,
for a value of the wrong shape, its key), raise nothing else (warnings are errors in the
test suite) and write nothing outside the run's directory."""

from __future__ import annotations

import copy
import json
import random
import shutil
from pathlib import Path

import pytest

from conftest import main_code
from test_fuzz_fold import JUNK, nodes, put

FINAL = "solutions/step_03_dof_06.fold"
LOG = "log.jsonl"


def read_doc(path: Path):
    """The JSON of ``path``; of the log (JSON lines), the list of its lines."""
    if path.name == LOG:
        return [json.loads(line) for line in path.read_text().splitlines()]
    return json.loads(path.read_text())


def write_doc(path: Path, doc) -> None:
    """Write ``doc`` as :func:`read_doc` reads it."""
    if path.name == LOG:
        path.write_text("".join(json.dumps(line, allow_nan=True) + "\n" for line in doc))
    else:
        path.write_text(json.dumps(doc, allow_nan=True))


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    """A small finished run with Steps 8-9 on every solution (DOF 9 -> 6, four solutions),
    without its report."""
    out = tmp_path_factory.mktemp("run") / "run"
    args = ["generate", "--surface", "bezier", "--seed", "1", "--pattern", "grid:4x4"]
    argv = [*args, "--target-dof", "6", "--check", "all", "--quiet", "--out", str(out)]
    assert main_code(argv) == 0
    shutil.rmtree(out / "figures")
    shutil.rmtree(out / "final")
    (out / "report.html").unlink()
    return out


class _Delete:
    def __repr__(self) -> str:
        return "DELETE"


DELETE = _Delete()
"""A mutation's value that deletes the key."""

MUTATIONS = [
    # (file, path, value, what the message names)
    ("summary.json", ("per_solution",), [1, 2], "'per_solution[0]' is 1, expected an object"),
    ("summary.json", ("verdict",), "passed", "'verdict' is \"passed\", expected an object"),
    ("summary.json", ("verdict",), {}, "'verdict' has no 'outcome', 'message'"),
    ("summary.json", ("verdict", "outcome"), 1, "'verdict.outcome' is 1, expected text"),
    ("summary.json", ("case", "surface", "plan_box_m"), [3], "'case.surface.plan_box_m' is [3]"),
    ("summary.json", ("case", "surface", "plan_box_m"), [3, "x"], "'case.surface.plan_box_m[1]'"),
    ("summary.json", ("case", "surface", "plan_box_m"), [1e400, 3], "plan_box_m[0]' is Infinity"),
    ("summary.json", ("case", "surface", "control_heights"), [1, 2], "control_heights[0]' is 1"),
    ("summary.json", ("case", "surface", "control_heights"), "x", "'case.surface.control_heigh"),
    ("summary.json", ("case", "surface", "name"), 5, "'case.surface.name' is 5, expected text"),
    ("summary.json", ("case", "surface"), [1], "'case.surface' is [1], expected an object"),
    ("summary.json", ("case",), "bezier", "'case' is \"bezier\", expected an object"),
    ("summary.json", ("case", "F_tol"), "1e-7", "'case.F_tol' is \"1e-7\", expected a finite"),
    ("summary.json", ("case", "dz_m"), {}, "'case.dz_m' is {}, expected a finite number or null"),
    ("summary.json", ("per_solution", 0, "development"), "x", "'per_solution[0].development'"),
    ("summary.json", ("per_solution", 0, "development", "D"), "big", 'development.D\' is "big"'),
    ("summary.json", ("per_solution", 3, "development", "flipped"), "1", "'per_solution[3].dev"),
    ("summary.json", ("per_solution", 0, "motion"), [1], "'per_solution[0].motion' is [1]"),
    ("summary.json", ("per_solution", 1, "motion", "max_length_error"), "e", "max_length_error"),
    ("summary.json", ("per_solution", 0, "deformation"), 5, "'per_solution[0].deformation' is 5"),
    ("summary.json", ("per_solution", 2, "deformation", "max_dl_mm"), [1], "max_dl_mm' is [1]"),
    ("summary.json", ("per_solution", 0, "verdicts"), "agree", "'per_solution[0].verdicts'"),
    ("summary.json", ("per_solution", 0, "step"), 1.5, "'per_solution[0].step' is 1.5"),
    ("summary.json", ("options",), [], "'options' is [], expected an object or null"),
    ("summary.json", ("options", "target_dof"), "6", "'options.target_dof' is \"6\""),
    (
        "summary.json",
        ("final_dof",),
        [6],
        "'final_dof' is [6], expected a whole number (64 bits) or null",
    ),
    ("summary.json", ("n_lock",), "$\\frac$", "'n_lock' is \"$\\\\frac$\""),
    ("summary.json", ("stop",), None, "'stop' is null, expected text"),
    ("summary.json", ("solutions",), "solutions/x.fold", "'solutions' is \"solutions/x.fold\""),
    ("summary.json", ("solutions", 0), "/etc/passwd", "'solutions[0]' is \"/etc/passwd\""),
    ("summary.json", ("solutions", 0), "../run/" + FINAL, "expected a file in the run's direc"),
    ("summary.json", ("solutions", 0), "", "'solutions[0]' is \"\", expected a file in the"),
    ("summary.json", ("per_solution",), DELETE, "not the summary of rigidfold generate (no per"),
    ("summary.json", ("schema_version",), 9, "summary.json' was written by run schema version 9"),
    ("summary.json", ("schema_version",), DELETE, "run schema version 0 (none recorded); this"),
    ("summary.json", ("schema_version",), "1", 'run schema version "1"; this rigidfold reads'),
    # log.jsonl as its list of lines: 0 the header, then one per attempt
    (LOG, (0,), {}, "line 1: {} is not the header of a run log (no 'schema_version')"),
    (LOG, (0, "schema_version"), 0, "log.jsonl' was written by run schema version 0; this"),
    (LOG, (1,), 1, "line 2: 1 is not a JSON object"),
    (LOG, (1, "outcome"), DELETE, "line 2: the line has no 'outcome'"),
    (LOG, (1, "dof"), DELETE, "line 2: the line has no 'dof'"),
    (LOG, (1, "index"), DELETE, "line 2: the line has no 'index'"),
    (LOG, (1, "dof"), "9", "line 2: 'dof' is \"9\", expected a whole"),
    (LOG, (1, "dof"), None, "line 2: 'dof' is null, expected a whole nu"),
    (LOG, (2, "F"), "small", "line 3: 'F' is \"small\", expected a fin"),
    (LOG, (2, "F"), 1e400, "line 3: 'F' is Infinity, expected a finite"),
    (LOG, (1, "index"), "0", "line 2: 'index' is \"0\", expected a who"),
    (LOG, (1, "index"), 2**64, "line 2: 'index' is 18446744073709551616"),
    (LOG, (2, "F"), 10**400, "line 3: 'F' is 10000000000000000000000"),
    ("summary.json", ("per_solution", 0, "dof"), -(2**63), "'per_solution[0].dof' is -9223"),
    (FINAL, ("rigidfold:deformation", "history"), "x", "'rigidfold:deformation.history' is \"x"),
    (FINAL, ("rigidfold:deformation", "history", 0), {}, "history[0]' has no 'load_factor'"),
    (FINAL, ("rigidfold:deformation", "history", 1, "max_dl_mm"), None, "history[1].max_dl_mm"),
    (FINAL, ("rigidfold:deformation",), [], "'rigidfold:deformation' is [], expected an object"),
    (FINAL, ("rigidfold:step",), "3", "'rigidfold:step' is \"3\", expected a whole number"),
]


def mutate(doc, path: tuple, value):
    """``doc`` with the value at ``path`` replaced by ``value`` (deleted for DELETE)."""
    if value is DELETE:
        parent = doc
        for step in path[:-1]:
            parent = parent[step]
        del parent[path[-1]]
        return doc
    return put(doc, path, copy.deepcopy(value))


def report(case: Path, capsys) -> tuple[int, str]:
    """``rigidfold report CASE``: exit code and stderr; no exception, no traceback."""
    try:
        code = main_code(["report", str(case)])
    except BaseException as exc:  # any escape is a failure, named with its case
        pytest.fail(f"{type(exc).__name__}: {exc}")
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, err


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rigidfold: error: "), err
    return lines[0]


@pytest.mark.parametrize(
    "file, path, value, words",
    MUTATIONS,
    ids=[f"{Path(f).name}:{'.'.join(map(str, p))}={v!r:.24}" for f, p, v, _ in MUTATIONS],
)
def test_a_damaged_summary_or_log_is_one_line_naming_the_file_and_key(
    run_dir, tmp_path, capsys, file, path, value, words
):
    case = shutil.copytree(run_dir, tmp_path / "run")
    doc = read_doc(case / file)
    write_doc(case / file, mutate(doc, path, value))
    code, err = report(case, capsys)
    assert code == 2, f"{file} {path} = {value!r}: exit {code}"
    line = one_line(err)
    assert str(case / file) in line or (file == "summary.json" and "summary.json" in line), line
    assert words in line, line
    assert not (case / "report.html").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]


MUTANTS = 60


def random_mutant(summary: dict, log: list, rng: random.Random) -> tuple[dict, list, list[str]]:
    """A copy of (summary, log) with 1 to 3 random values replaced by junk or keys deleted."""
    summary, log = copy.deepcopy(summary), copy.deepcopy(log)
    done = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        name, doc = rng.choice([("summary.json", summary), (LOG, log)])
        places = [(p, v) for p, v in nodes(doc) if p]
        path, _ = rng.choice(places)
        if rng.random() < 0.25 and isinstance(path[-1], str):
            mutate(doc, path, DELETE)
            done.append(f"{name}: del {list(path)}")
        else:
            value = rng.choice(JUNK)
            mutate(doc, path, value)
            done.append(f"{name}: {list(path)} = {value!r:.40}")
    return summary, log, done


def test_random_damage_to_summary_and_log_ends_in_an_exit_code(run_dir, tmp_path, capsys):
    summary = json.loads((run_dir / "summary.json").read_text())
    log = read_doc(run_dir / LOG)
    rng = random.Random("fuzz-summary")
    codes = []
    for k in range(MUTANTS):
        new_summary, new_log, done = random_mutant(summary, log, rng)
        case = shutil.copytree(run_dir, tmp_path / f"case{k}")
        write_doc(case / "summary.json", new_summary)
        write_doc(case / LOG, new_log)
        label = f"mutant {k} ({'; '.join(done)})"
        code, err = report(case, capsys)
        assert code in (0, 2), f"{label}: exit {code}"
        if code == 2:
            line = one_line(err)
            assert "summary.json" in line or LOG in line or ".fold" in line, label
        codes.append(code)
        shutil.rmtree(case)
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    assert codes.count(0) >= 3 and codes.count(2) >= 10, codes  # both kinds of case happen
