"""Target surfaces: values, exact gradients, CasADi backend, symmetry, safe parsing."""

from __future__ import annotations

import json
import warnings

import casadi as ca
import numpy as np
import pytest

from conftest import dome_mesh
from rigidfold.generate.specs import parse_expression, parse_surface_spec
from rigidfold.surfaces import (
    SURFACES,
    Bezier,
    Dome,
    ExpressionSurface,
    HyperbolicParaboloid,
    MeshSurface,
    MirrorPlane,
    surface_of,
)


def get_surface(name, *, seed=None, expr=None):
    """The surface that ``--surface NAME --seed SEED --expr EXPR`` names."""
    return surface_of(parse_surface_spec(name, seed=seed, expr=expr))


def expression_surface(text, mirror_planes=()):
    """The surface of ``--surface expr --expr TEXT``."""
    return ExpressionSurface(parse_expression(text), mirror_planes)


FACTORIES = {
    "bezier0": lambda: Bezier(0),
    "bezier7": lambda: Bezier(7),
    "dome": Dome,
    "hp": HyperbolicParaboloid,
    "expr": lambda: expression_surface("0.3*sin(x)*cos(y) + 0.1*x**2 - sqrt(1 + y)/3"),
    # scaled to a pattern's plan box (which holds the sample points in [0, 3]^2)
    "bezier-box": lambda: Bezier(2, box=(12.0, 8.0)),
    "dome-box": lambda: Dome(box=(3.5, 6.0)),
    "hp-box": lambda: HyperbolicParaboloid(box=(4.0, 7.0)),
    "mesh": lambda: MeshSurface(*dome_mesh(41)),
}


@pytest.fixture(params=list(FACTORIES))
def surface(request):
    return FACTORIES[request.param]()


def _plan_points(n=50, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(0.1, 2.9, n), rng.uniform(0.1, 2.9, n)


def test_gradient_matches_central_differences(surface):
    x, y = _plan_points()
    gx, gy = surface.gradient(x, y)
    h = 1e-6
    fx = (surface.height(x + h, y) - surface.height(x - h, y)) / (2 * h)
    fy = (surface.height(x, y + h) - surface.height(x, y - h)) / (2 * h)
    assert np.linalg.norm(gx - fx) / np.linalg.norm(fx) < 1e-6
    assert np.linalg.norm(gy - fy) / np.linalg.norm(fy) < 1e-6


def test_hessian_matches_differences_of_the_gradient(surface):
    x, y = _plan_points()
    fxx, fxy, fyy = surface.hessian(x, y)
    h = 1e-6
    gx_p, gy_p = surface.gradient(x + h, y)
    gx_m, gy_m = surface.gradient(x - h, y)
    hx_p, hy_p = surface.gradient(x, y + h)
    hx_m, hy_m = surface.gradient(x, y - h)
    for exact, fd in (
        (fxx, (gx_p - gx_m) / (2 * h)),
        (fxy, (gy_p - gy_m) / (2 * h)),
        (fxy, (hx_p - hx_m) / (2 * h)),
        (fyy, (hy_p - hy_m) / (2 * h)),
    ):
        assert np.abs(exact - fd).max() <= 1e-6 * max(1.0, np.abs(fd).max())
    assert fxx.shape == x.shape


def test_closed_form_hessian_equals_automatic_differentiation(surface):
    from rigidfold.surfaces.builtin import Surface

    x, y = _plan_points(30, 2)
    for mine, ad in zip(surface.hessian(x, y), Surface.hessian(surface, x, y), strict=True):
        assert np.allclose(mine, ad, rtol=1e-12, atol=1e-12)


def test_casadi_backend_equals_numpy(surface):
    x, y = _plan_points(20, 1)
    sx, sy = ca.SX.sym("x", 20), ca.SX.sym("y", 20)
    fun = ca.Function("z", [sx, sy], [surface.height(sx, sy, xp=ca)])
    assert np.allclose(np.asarray(fun(x, y)).ravel(), surface.height(x, y), rtol=1e-14)


def test_height_keeps_array_shape(surface):
    x = np.full((2, 3), 1.0)
    assert np.shape(surface.height(x, x)) == (2, 3)


def test_dome_values():
    dome = Dome()
    corners = np.array([0.0, 3.0, 0.0, 3.0]), np.array([0.0, 0.0, 3.0, 3.0])
    assert np.allclose(dome.height(*corners), 0.0, atol=1e-12)
    assert dome.height(np.array([1.5]), np.array([1.5]))[0] == pytest.approx(1.5)


def test_hp_values():
    hp = HyperbolicParaboloid()
    z = hp.height(np.array([0.0, 3.0, 0.0, 3.0]), np.array([0.0, 0.0, 3.0, 3.0]))
    assert np.allclose(z, [0.9, -0.9, -0.9, 0.9])
    assert z.max() - z.min() == pytest.approx(1.8)


def test_bezier_control_heights_and_convex_hull():
    bez = Bezier(3)
    h = np.random.default_rng(3).uniform(0, 3, (4, 4))
    assert np.array_equal(bez.heights, h)
    z = bez.height(np.array([0.0, 3.0, 0.0, 3.0]), np.array([0.0, 0.0, 3.0, 3.0]))
    assert np.allclose(z, [h[0, 0], h[3, 0], h[0, 3], h[3, 3]])
    gx, gy = np.meshgrid(np.linspace(0, 3, 31), np.linspace(0, 3, 31))
    zz = bez.height(gx, gy)
    assert zz.min() >= h.min() - 1e-12 and zz.max() <= h.max() + 1e-12
    assert Bezier(3).metadata()["control_heights"] == h.tolist()


@pytest.mark.parametrize("surface", [Dome(), HyperbolicParaboloid()], ids=["dome", "hp"])
def test_mirror_symmetry(surface):
    x, y = _plan_points(100, 2)
    for plane in surface.mirror_planes:
        image = plane.reflect(np.column_stack([x, y]))
        assert np.allclose(surface.height(*image.T), surface.height(x, y), atol=1e-12)


def test_hp_not_symmetric_about_midlines():
    hp = HyperbolicParaboloid()
    x, y = _plan_points(10, 3)
    image = MirrorPlane(1.0, 0.0, -1.5).reflect(np.column_stack([x, y]))
    assert not np.allclose(hp.height(*image.T), hp.height(x, y))


def test_mirror_plane_text():
    assert [str(p) for p in Dome().mirror_planes] == ["x = 1.5", "y = 1.5"]
    assert [str(p) for p in HyperbolicParaboloid().mirror_planes] == ["x - y = 0", "x + y = 3"]
    assert str(MirrorPlane(-2.0, 1.0, 1.0)) == "-2x + y = -1"


def test_mirror_plane_geometry():
    plane = MirrorPlane(2.0, 2.0, -6.0)  # x + y = 3, unnormalised
    xy = np.array([[0.0, 0.0], [3.0, 3.0], [1.0, 2.0]])
    assert np.allclose(plane.signed_distance(xy), [-3 / np.sqrt(2), 3 / np.sqrt(2), 0.0])
    assert np.allclose(plane.reflect(xy), [[3.0, 3.0], [0.0, 0.0], [1.0, 2.0]])
    assert np.allclose(plane.reflect(plane.reflect(xy)), xy)
    with pytest.raises(ValueError, match="not a mirror plane"):
        MirrorPlane(0.0, 0.0, 1.0)


@pytest.mark.parametrize(
    "text",
    [
        "1",
        "x",
        "-x + 2*y",
        "sin(x)*cos(y)",
        "exp(-((x-1.5)**2 + (y-1.5)**2))",
        "abs(x - y)",
        "atan2(y, x + 1)",
        "pi*e",
        "max(x, y) - min(x, 1)",
        "hypot(x, y)",
        "sqrt(1 + x**2)",
    ],
)
def test_accepted_expressions(text):
    surface = get_surface("expr", expr=text)
    x, y = _plan_points(5, 4)
    assert np.all(np.isfinite(surface.height(x, y)))


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("__import__('os')", "function '__import__' is not allowed"),
        ("x.real", "attribute access"),
        ("x.__class__.__bases__", "attribute access"),
        ("__import__('os').system('true')", "attribute access is not allowed"),
        ("(lambda: 1)()", "a lambda is not allowed"),
        ("(1)(2)", "by plain name"),
        ("x[0]", "subscripting is not allowed"),
        ("z + 1", "name 'z' is not allowed"),
        ("open('f')", "function 'open' is not allowed"),
        ("eval('1')", "function 'eval' is not allowed"),
        ("x if y else 1", "conditional"),
        ("x < y", "a comparison is not allowed"),
        ("x or y", "boolean"),
        ("sin(x=1)", "keyword"),
        ("sin(x, y)", "takes 1 argument"),
        ("atan2(x)", "takes 2 arguments"),
        ("sin(*x)", "starred"),
        ("sin", "must be called"),
        ("", "empty expression"),
        ("   ", "empty expression"),
        ("x +", "invalid expression 'x \\+': "),
        ("x\n+ 1\n+", "invalid expression"),
        ("-" * 999 + "x", "nested deeper than"),
        ("+".join(["x"] * 600), "longer than 1000 characters"),
        ("1j*x", "only real numbers"),
        ("'a'", "only real numbers"),
        ("True", "only real numbers"),
        ("1" * 400, "too large"),
        ("[x]", "a list is not allowed"),
        ("x // 2", r"only \+ - \* / \*\*"),
        ("(x := 2)", "assignment"),
        ("f'{x}'", "an f-string is not allowed"),
        ("[i for i in x]", "a comprehension is not allowed"),
        ("not x", r"only unary \+ and -"),
    ],
)
def test_refused_expressions(text, reason):
    with pytest.raises(ValueError, match=reason) as info:
        expression_surface(text)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(("refused expression", "invalid expression", "empty expression"))


def test_refused_expression_is_never_evaluated(monkeypatch):
    from rigidfold.surfaces import expression

    calls = []
    monkeypatch.setattr(expression, "evaluate", lambda *a, **k: calls.append(a))
    with pytest.raises(ValueError):
        expression_surface("__import__('os').system('true')")
    assert calls == []


def test_refused_expression_has_no_side_effect(tmp_path):
    marker = tmp_path / "touched"
    for text in [
        f"__import__('pathlib').Path({str(marker)!r}).touch()",
        f"open({str(marker)!r}, 'w')",
        f"sin(x) + (__import__('pathlib').Path({str(marker)!r}).touch() or 0)",
    ]:
        with pytest.raises(ValueError, match="refused expression"):
            expression_surface(text)
    assert not marker.exists()


def test_expression_shapes_and_metadata():
    surface = expression_surface("  0.5 *  x*y ", mirror_planes=(MirrorPlane(1, -1, 0),))
    assert surface.metadata() == {"name": "expr", "expression": "0.5 * x*y"}
    assert repr(surface) == "ExpressionSurface('0.5 * x*y')"
    assert [str(p) for p in surface.mirror_planes] == ["x - y = 0"]
    z = surface.height(np.arange(3.0)[:, None], np.arange(4.0)[None, :])
    assert z.shape == (3, 4) and z[2, 3] == pytest.approx(3.0)
    gx, gy = surface.gradient(np.full((2, 3), 2.0), np.full((2, 3), 4.0))
    assert gx.shape == gy.shape == (2, 3)
    assert np.allclose(gx, 2.0) and np.allclose(gy, 1.0)
    gx, gy = surface.gradient(2.0, 4.0)
    assert np.shape(gx) == () and float(gy) == pytest.approx(1.0)
    gx, gy = surface.gradient(np.zeros(0), np.zeros(0))
    assert gx.shape == gy.shape == (0,)
    constant = expression_surface("2")
    assert np.array_equal(constant.height(np.zeros(4), np.zeros(4)), np.full(4, 2.0))
    assert np.array_equal(constant.gradient(np.zeros(4), np.zeros(4))[0], np.zeros(4))
    with pytest.raises(TypeError, match="must be text"):
        parse_expression(1.0)
    with pytest.raises(TypeError, match="takes an Expression"):
        ExpressionSurface("2")


@pytest.mark.parametrize("text", ["1/0", "log(x - 5)", "10.0**1000", "sqrt(-1 - x)"])
def test_non_finite_expression_reported(text):
    surface = expression_surface(text)
    with pytest.raises(ValueError, match="not finite at"):
        surface.check_finite(np.array([0.0, 1.0]), np.array([0.0, 1.0]))


def test_finite_expression_passes_check():
    expression_surface("log(x + 1) / (y + 1)").check_finite(*_plan_points())


def test_get_surface_and_metadata():
    assert isinstance(get_surface("dome"), Dome)
    assert isinstance(get_surface("hp"), HyperbolicParaboloid)
    assert get_surface("bezier").seed == 0
    assert get_surface("bezier", seed=5).seed == 5
    for name in SURFACES:
        surface = get_surface(name, seed=1, expr="x*y")
        meta = json.loads(json.dumps(surface.metadata()))
        assert meta["name"] == surface.name == name
        assert "\n" not in repr(surface) and len(repr(surface)) < 80
    assert repr(Bezier(4)) == "Bezier(4)"
    flat = Bezier.from_heights(np.ones((4, 4)))
    assert flat.metadata()["seed"] is None
    assert np.allclose(flat.height(*_plan_points()), 1.0)
    with pytest.raises(ValueError, match="finite"):
        Bezier.from_heights(np.ones((3, 4)))


def test_get_surface_errors():
    with pytest.raises(ValueError, match=r"unknown surface 'cone' \(choose from bezier, dome"):
        get_surface("cone")
    with pytest.raises(ValueError, match="needs an expression"):
        get_surface("expr")
    with pytest.raises(ValueError, match="non-negative integer"):
        get_surface("bezier", seed=-1)


@pytest.mark.parametrize("box", [(3.0, 3.0), (3.5, 6.0)], ids=["square", "box"])
def test_dome_is_defined_past_its_rim(box):
    """A solve may move a vertex past the sphere's rim: the dome continues there along the
    root's tangent (C1), finite, its gradient and Hessian exact, numpy and CasADi alike; over
    the plan box it is the sphere."""
    from rigidfold.surfaces.builtin import Surface as BaseSurface

    dome = Dome(box=box)
    angle = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    r = np.sqrt(dome.radius**2 - dome.u0)  # where the tangent takes over
    for radius in (0.9 * r, 0.999 * r, 1.001 * r, dome.radius, 1.5 * dome.radius):
        x, y = dome.cx + radius * np.cos(angle), dome.cy + radius * np.sin(angle)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            z, (gx, gy), hess = dome.height(x, y), dome.gradient(x, y), dome.hessian(x, y)
        assert np.isfinite(z).all() and all(np.isfinite(h).all() for h in hess)
        h = 1e-6
        fx = (dome.height(x + h, y) - dome.height(x - h, y)) / (2 * h)
        fy = (dome.height(x, y + h) - dome.height(x, y - h)) / (2 * h)
        assert np.allclose(gx, fx, rtol=1e-6, atol=1e-6) and np.allclose(gy, fy, atol=1e-6)
        if abs(radius / r - 1) > 0.01:  # off the seam, where d2z jumps
            ad = BaseSurface.hessian(dome, x, y)
            for mine, other in zip(hess, ad, strict=True):
                assert np.allclose(mine, other, rtol=1e-10, atol=1e-10)
        sx, sy = ca.SX.sym("x", len(x)), ca.SX.sym("y", len(x))
        fun = ca.Function("z", [sx, sy], [dome.height(sx, sy, xp=ca)])
        assert np.allclose(np.asarray(fun(x, y)).ravel(), z, rtol=1e-14)
    gx, gy = np.meshgrid(np.linspace(0, box[0], 13), np.linspace(0, box[1], 13))
    sphere = dome.centre_z + np.sqrt(dome.radius**2 - (gx - dome.cx) ** 2 - (gy - dome.cy) ** 2)
    assert np.array_equal(dome.height(gx, gy), sphere)
