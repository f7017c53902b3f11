"""The packages show the layers (docs/architecture.md): every import of a module of rigidfold,
at the top of a file or inside a function, goes to its own layer or one below, and no two
packages import each other."""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "rigidfold"

LAYERS: tuple[tuple[str, ...], ...] = (
    ("errors", "outcomes", "protocols", "flags", "config", "material"),
    ("runtime",),
    ("surfaces", "mesh", "io", "patterns"),
    ("optimize", "frame", "mechanism", "selection", "develop", "deform"),
    ("exports", "fabricate", "structure", "drive"),
    ("generate",),
    ("rundir",),
    ("reporting",),
    ("pipeline",),
    ("study",),
    ("cli",),
)
ENTRIES = ("__init__", "__main__", "pinned")  # the package and its process entries
KNOWN_UPWARD: set[tuple[str, str]] = set()
"""Imports allowed to go up a layer: none."""
LAYER_OF = {name: i for i, names in enumerate(LAYERS) for name in names}


def _module(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, module: str) -> set[str]:
    out: set[str] = set()
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("rigidfold"))
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                root = package.split(".")
                base = ".".join(root[: len(root) - node.level + 1] + ([base] if base else []))
            if base == "rigidfold":  # from rigidfold import patterns
                out.update(f"rigidfold.{a.name}" for a in node.names)
            elif base.startswith("rigidfold."):
                out.add(base)
    return out


def _top(module: str) -> str:
    return module.split(".")[1] if module.count(".") else "__init__"


def _graph() -> dict[str, set[str]]:
    return {
        _module(p): _imports(p, _module(p))
        for p in SRC.rglob("*.py")
        if "__pycache__" not in p.parts
    }


def test_every_package_has_a_layer():
    tops = {_top(m) for m in _graph()} - set(ENTRIES)
    assert tops <= set(LAYER_OF), f"packages without a layer: {sorted(tops - set(LAYER_OF))}"


def test_no_import_goes_up_a_layer():
    upward = []
    for module, targets in _graph().items():
        a = _top(module)
        if a in ENTRIES:
            continue
        for target in targets:
            b = _top(target)
            if b in ENTRIES or b not in LAYER_OF:  # the package itself (__version__)
                continue
            if LAYER_OF[b] > LAYER_OF[a] and (module, target) not in KNOWN_UPWARD:
                upward.append(f"{module} -> {target}")
    assert not upward, "imports up a layer:\n" + "\n".join(sorted(upward))


def test_no_two_packages_import_each_other_except_the_named_one():
    edges: dict[str, set[str]] = {}
    for module, targets in _graph().items():
        for target in targets:
            if (module, target) in KNOWN_UPWARD:
                continue
            a, b = _top(module), _top(target)
            if a != b and a not in ENTRIES and b not in ENTRIES:
                edges.setdefault(a, set()).add(b)
    pairs = sorted(
        {tuple(sorted((a, b))) for a in edges for b in edges[a] if a in edges.get(b, ())}
    )
    assert not pairs, f"packages importing each other: {pairs}"
