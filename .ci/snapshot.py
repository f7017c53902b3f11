"""A snapshot of what rigidfold does, to compare before and after a change that must not
change behaviour (issue 46, item 5): five fixed ``generate`` runs (plain; thick panels; the
structure check; every check with the lookahead; the drive), a small study and every
command's ``--help``, with every time and host-dependent value dropped.

    python .ci/snapshot.py OUT                      # the code of this checkout (its src/)
    git worktree add /tmp/before <commit>
    python .ci/snapshot.py --src /tmp/before OUT_BEFORE   # the code of another checkout
    diff -r OUT_BEFORE OUT

Each run goes through ``python -m rigidfold.pinned``, so the numbers are those of the pinned
numerics on any machine. Takes a few minutes.
"""

from __future__ import annotations

import argparse
import json
import os
import sqlite3
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RUNS = {
    "plain": "--surface bezier --seed 1 --pattern 1 --criterion shat --no-deform",
    "thick": "--surface dome --pattern grid:4x4 --size 3x3 --thickness 18mm --no-deform",
    "struct": "--surface dome --pattern grid:4x4 --size 3x3 --structure --material steel "
    "--no-deform",
    "all": "--surface hp --pattern grid:4x4 --size 3x3 --check all --lookahead",
    "deploy": "--surface dome --pattern grid:4x4 --size 3x3 --thickness 18mm --deploy --no-deform",
}
COMMANDS = (
    "generate report analyze develop deform export structure fabricate deploy study "
    "study-report optimize"
).split()
DROP = {"time_s", "wall_s", "time", "t", "elapsed_s", "started", "finished", "created"}
DROP |= {"numerics", "host", "python", "versions", "version", "worker"}


def clean(x):
    """``x`` without times and host-dependent values, keys sorted."""
    if isinstance(x, dict):
        return {
            k: clean(v)
            for k, v in sorted(x.items())
            if k not in DROP and not k.startswith("time") and not k.endswith(("_time", "_s"))
        }
    if isinstance(x, list):
        return [clean(v) for v in x]
    return x


SRC = [ROOT / "src"]  # the code run: this checkout's, or --src's


def command(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(SRC[0])}
    cli = [sys.executable, "-m", "rigidfold.pinned", sys.executable, "-m", "rigidfold.cli"]
    return subprocess.run([*cli, *args], env=env, capture_output=True, text=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder for the snapshot (made)")
    parser.add_argument("--src", type=Path, default=ROOT, help="the checkout whose code runs")
    given = parser.parse_args()
    out, SRC[0] = given.out, given.src.resolve() / "src"
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as work:
        w = Path(work)
        for name, args in RUNS.items():
            done = command("generate", *args.split(), "--out", str(w / name), "--quiet")
            (out / f"{name}.stdout").write_text(
                done.stdout.replace(str(w), "WORK") + f"rc {done.returncode}\n"
            )
            for file in ("summary.json", "log.jsonl"):
                path = w / name / file
                if not path.exists():
                    continue
                if file.endswith(".jsonl"):
                    lines = path.read_text().splitlines()
                    text = "".join(
                        json.dumps(clean(json.loads(x)), sort_keys=True) + "\n" for x in lines
                    )
                else:
                    text = json.dumps(clean(json.loads(path.read_text())), indent=1) + "\n"
                (out / f"{name}.{file}").write_text(text.replace(str(w), "WORK"))
            files = sorted(
                str(p.relative_to(w / name)) for p in (w / name).rglob("*") if p.is_file()
            )
            (out / f"{name}.files").write_text("\n".join(files) + "\n")
        for c in ["", *COMMANDS]:
            (out / f"help_{c}.txt").write_text(command(*([c] if c else []), "--help").stdout)
        db = w / "study.sqlite"
        done = command(
            "study", "--patterns", "1", "--criteria", "s,shat", "--surfaces", "2",
            "--workers", "1", "--db", str(db),
        )  # fmt: skip
        (out / "study.stdout").write_text(
            done.stdout.replace(str(w), "WORK") + f"rc {done.returncode}\n"
        )
        rows = []
        with sqlite3.connect(db) as con:
            tables = con.execute("select name from sqlite_master where type='table' order by name")
            for (table,) in tables.fetchall():
                cols = [r[1] for r in con.execute(f"pragma table_info({table})")]
                for row in con.execute(f"select * from {table} order by rowid"):
                    record = clean(dict(zip(cols, row, strict=True)))
                    rows.append(f"{table} {json.dumps(record, sort_keys=True, default=str)}")
        (out / "study.rows").write_text("\n".join(rows).replace(str(w), "WORK") + "\n")
    print(f"snapshot in {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
