"""Splines and volumes from numpy arrays, their arrays back, evaluation, Jacobians and both
inverse maps: shapes, the reference evaluator, thread counts, refinement, errors, and arrays
that outlive the objects they came from."""

import gc

import numpy as np
import pytest

import trivox
from conftest import ANNULUS, bits, random_params


def annulus_spline():
    """The bundled exact NURBS quarter annulus, built from arrays (orders 2 x 3 x 2)."""
    h = np.sqrt(0.5)
    pts, w = [], []
    for z in (0.0, 10.0):
        for (c, s, wt) in ((1, 0, 1.0), (1, 1, h), (0, 1, 1.0)):
            for r in (20.0, 30.0):
                pts.append([r * c, r * s, z])
                w.append(wt)
    return trivox.Spline([2, 3, 2], [[0, 0, 1, 1], [0, 0, 0, 1, 1, 1], [0, 0, 1, 1]], pts, w)


def test_flat_and_grid_points_give_the_same_spline():
    s = annulus_spline()
    assert s.param_dim == 3 and s.point_dim == 3 and s.is_rational
    assert s.num_ctrl == (2, 3, 2)
    grid = s.control_grid
    assert grid.shape == (2, 3, 2, 3)
    # [i, j, k] is control point i + n_u (j + n_v k) of the u-fastest list.
    for i in range(2):
        for j in range(3):
            for k in range(2):
                assert (grid[i, j, k] == s.points[i + 2 * (j + 3 * k)]).all()
    again = trivox.Spline(s.orders, s.knots, grid, s.weight_grid)
    assert again == s
    assert trivox.Spline(s.orders, s.knots, s.points, s.weights) == s
    assert not (trivox.Spline(s.orders, s.knots, s.points) == s)


def test_the_bundled_file_and_the_arrays_agree():
    from_file = trivox.read(str(ANNULUS)).volumes()[0]
    from_arrays = trivox.Volume(annulus_spline())
    p = random_params(from_arrays, 200, 1)
    np.testing.assert_allclose(from_file.evaluate(p), from_arrays.evaluate(p), rtol=0, atol=1e-12)
    assert from_file.source[1] == 0 and from_arrays.source is None


def test_evaluate_keeps_the_leading_shape_and_matches_the_reference_evaluator(column):
    p = random_params(column, 24, 2).reshape(2, 3, 4, 3)
    x = column.evaluate(p)
    assert x.shape == (2, 3, 4, 3) and x.dtype == np.float64
    ref = column.spline.evaluate(p)
    np.testing.assert_allclose(x, ref, rtol=1e-13, atol=1e-12)
    one = column.evaluate(p[1, 2, 3])
    assert one.shape == (3,) and bits(one) == bits(x[1, 2, 3])
    # Lists and integer arrays are converted.
    assert bits(column.evaluate([[0, 1, 2]])) == bits(column.evaluate(np.array([[0.0, 1.0, 2.0]])))


def test_jacobian_columns_are_the_partial_derivatives(column):
    p = random_params(column, 50, 3)
    values, jac = column.jacobian(p, with_values=True)
    assert jac.shape == (50, 3, 3)
    assert bits(values) == bits(column.evaluate(p))
    partials = column.spline.partials(p)  # [..., d, c] = d V_c / d p_d
    np.testing.assert_allclose(jac, np.swapaxes(partials, 1, 2), rtol=1e-12, atol=1e-9)
    assert bits(column.jacobian(p)) == bits(jac)


def test_out_arrays_are_written_and_returned(column):
    p = random_params(column, 5000, 9)
    buffer = np.full((5000, 3), np.nan)
    assert column.evaluate(p, out=buffer) is buffer
    assert bits(buffer) == bits(column.evaluate(p))
    jac = np.empty((5000, 3, 3))
    values = np.empty((5000, 3))
    assert column.jacobian(p, out=jac) is jac
    v, j = column.jacobian(p, with_values=True, out=(values, np.empty((5000, 3, 3))))
    assert v is values and bits(j) == bits(jac) and bits(v) == bits(buffer)
    with pytest.raises(ValueError, match="shape"):
        column.evaluate(p, out=np.empty((4999, 3)))
    with pytest.raises(ValueError, match="C-contiguous"):
        column.evaluate(p, out=np.empty((3, 5000)).T)
    with pytest.raises(TypeError, match="float64"):
        column.evaluate(p, out=np.empty((5000, 3), dtype=np.float32))


def test_results_are_the_same_bits_for_any_thread_count(column):
    p = random_params(column, 20000, 4)
    x = column.evaluate(p, threads=1)
    assert bits(column.evaluate(p, threads=0)) == bits(x)
    assert bits(column.evaluate(p, threads=3)) == bits(x)
    a, b = column.invert(x, threads=1), column.invert(x, threads=0)
    for field in a._fields:
        assert bits(getattr(a, field)) == bits(getattr(b, field)), field
    g1, g2 = column.invert_global(x[:3000], threads=1), column.invert_global(x[:3000], threads=2)
    for field in g1._fields:
        assert bits(getattr(g1, field)) == bits(getattr(g2, field)), field


def test_newton_finds_the_parameters_of_points_inside(column):
    p = random_params(column, 500, 5)
    x = column.evaluate(p)
    r = column.invert(x)  # from the domain's centre
    assert r.uvw.shape == (500, 3) and r.status.dtype == np.uint8 and r.iterations.dtype == np.int32
    assert (r.status == trivox.InverseStatus.CONVERGED).all()
    assert (r.residual <= 1e-8).all()
    np.testing.assert_allclose(r.uvw, p, atol=1e-8)
    # A hint per point, or one for all.
    near = column.invert(x, p + 1e-3)
    assert (near.iterations <= r.iterations).all() and (near.status == 0).all()
    one = column.invert(x[:3], [1.5, 1.5, 1.5])
    assert bits(one.uvw) == bits(r.uvw[:3])
    with pytest.raises(ValueError, match="hint"):
        column.invert(x, p[:10])


def test_newton_stops_on_the_face_below_a_point_above_the_volume(column):
    above = column.evaluate([[1.5, 1.5, 3.0]]) + [0, 0, 1]
    r = column.invert(above, [1.5, 1.5, 2.9], certified=False)
    assert r.status[0] in (trivox.InverseStatus.OUTSIDE, trivox.InverseStatus.NO_CONVERGENCE)
    assert r.uvw[0, 2] == 3.0  # held on the face w = 3
    assert abs(r.residual[0] - 1.0) < 0.1
    box = trivox.Volume(trivox.Spline([2, 2, 2], [[0, 0, 1, 1]] * 3,
                                      [[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)]))
    r = box.invert([[0.5, 0.5, 1.5]])
    assert r.status[0] == trivox.InverseStatus.OUTSIDE and r.uvw[0].tolist() == [0.5, 0.5, 1.0]
    # Certified (the default), the same point is proved outside: the same status, Newton's iterate.
    proved = column.invert(above, [1.5, 1.5, 2.9])
    assert proved.status[0] == trivox.InverseStatus.OUTSIDE and proved.uvw[0, 2] == 3.0


def test_invert_is_certified_by_default_on_a_revolved_solid():
    """A solid cylinder revolved from a rectangle that touches the z axis: from the domain's
    centre Newton alone stops SINGULAR for about half of its points (the axis is where det J
    vanishes); the default finds every point inside and proves the points beyond outside.
    Statuses print by name."""
    profile = trivox.Spline([2, 2], [[0, 0, 1, 1], [0, 0, 1, 1]], [[0, 0, 0], [10, 0, 0], [0, 0, 10], [10, 0, 10]])
    ring = trivox.revolve(profile).volume
    rng = np.random.default_rng(3)
    lo, hi = ring.domain[:, 0], ring.domain[:, 1]
    p = lo + (hi - lo) * rng.uniform(0.001, 0.999, (2000, 3))
    x = ring.evaluate(p)
    newton = ring.invert(x, certified=False)
    r = ring.invert(x)
    assert (r.status == trivox.InverseStatus.CONVERGED).all(), np.bincount(r.status)
    np.testing.assert_allclose(ring.evaluate(r.uvw), x, atol=1e-6)
    # The reported failure: Newton alone from the centre leaves points inside unsolved.
    assert (newton.status == trivox.InverseStatus.SINGULAR).sum() > 500
    outside = ring.invert([[0.0, 0.0, -1.0], [20.0, 0.0, 5.0], [7.0, 0.0, 11.0]])
    assert (outside.status == trivox.InverseStatus.OUTSIDE).all()
    assert repr(outside.statuses.tolist()) == "[OUTSIDE, OUTSIDE, OUTSIDE]"
    assert str(trivox.InverseStatus.CONVERGED) == "CONVERGED" and trivox.InverseStatus.CONVERGED == 0
    g = ring.invert_global([[0.0, 7.0, 5.0]])  # off the seam at angle 0, where two faces meet
    assert g.statuses.shape == (1,) and str(g.statuses[0]) == "UNIQUE"


def test_the_global_solver_lists_every_preimage_with_offsets(column):
    p = random_params(column, 300, 6)
    x = np.concatenate([column.evaluate(p), column.bounds[1] + 5.0 + np.zeros((7, 3))])
    g = column.invert_global(x)
    assert g.offsets.shape == (308,) and g.offsets[0] == 0 and g.offsets[-1] == len(g.uvw)
    counts = np.diff(g.offsets)
    assert (g.status[:300] == trivox.GlobalStatus.UNIQUE).all() and (counts[:300] == 1).all()
    assert (g.status[300:] == trivox.GlobalStatus.NONE).all() and (counts[300:] == 0).all()
    np.testing.assert_allclose(g.uvw, p, atol=1e-8)
    assert (g.det > 0).all() and (g.residual <= 1e-8).all()
    # The tolerances are keyword arguments: a looser one settles with fewer iterations.
    loose = column.invert_global(x[:300], residual_tolerance_model=1e-3)
    assert (loose.residual <= 1e-3).all()
    with pytest.raises(ValueError, match="residual_tolerance_model"):
        column.invert_global(x, residual_tolerance_model=0)


def test_folded_volume_has_two_preimages():
    # A triquadratic unit cube whose middle control point is pulled far above the top: along
    # the middle column z rises above 1 and comes back, so points just above the top face
    # there have two preimages, with det J of opposite signs.
    pts = []
    for k in range(3):
        for j in range(3):
            for i in range(3):
                z = 5.0 if (i, j, k) == (1, 1, 1) else k / 2
                pts.append([i / 2, j / 2, z])
    vol = trivox.Volume([3, 3, 3], [[0, 0, 0, 1, 1, 1]] * 3, pts)
    assert vol.check_jacobian().classification == "folded"
    g = vol.invert_global([[0.5, 0.5, 1.05]])
    assert g.status[0] == trivox.GlobalStatus.MULTIPLE and g.offsets[1] == 2
    assert g.det[0] * g.det[1] < 0
    np.testing.assert_allclose(vol.evaluate(g.uvw), [[0.5, 0.5, 1.05]] * 2, atol=1e-8)


def test_refinement_keeps_the_geometry_and_the_type(column):
    p = random_params(column, 100, 7)
    for changed in (trivox.elevate_degree(column, "u", 1), trivox.insert_knot(column, 2, 1.25, 2),
                    trivox.Volume(column.spline.reversed("v").reversed("v"))):
        assert isinstance(changed, trivox.Volume)
        np.testing.assert_allclose(changed.evaluate(p), column.evaluate(p), atol=1e-10)
    assert trivox.elevate_degree(column, "w").orders == [4, 4, 5]
    left, right = column.spline.split("u", 1.0)
    assert left.domain[0].tolist() == [0.0, 1.0] and right.domain[0].tolist() == [1.0, 3.0]


def test_itd_text_reads_back_to_the_same_doubles(column, tmp_path):
    path = tmp_path / "round.itd"
    vol = trivox.Volume(annulus_spline())
    trivox.write(str(path), [column, vol])
    back = trivox.read(str(path)).volumes()
    assert back[0] == column and back[1] == vol
    assert trivox.read_itd(trivox.to_itd([vol])).volumes()[0] == vol
    with pytest.raises(ValueError, match=r"\.itd"):
        trivox.write(str(tmp_path / "x.stl"), [vol])
    # One volume (or spline) on its own, not in a list.
    trivox.write(tmp_path / "one.itd", column)
    assert trivox.read(str(tmp_path / "one.itd")).volumes() == [column]
    trivox.write(tmp_path / "one.xml", column.spline)
    assert trivox.read(str(tmp_path / "one.xml")).volumes() == [column]


@pytest.mark.parametrize("ext", [".xml", ".g2"])
def test_gismo_and_gotools_files_read_back_to_the_same_doubles(column, tmp_path, ext):
    vol = trivox.Volume(annulus_spline())  # rational: the weights must survive too
    path = tmp_path / ("round" + ext)
    trivox.write(path, [column, vol])
    back = trivox.read(str(path)).volumes()
    assert len(back) == 2 and back[0] == column and back[1] == vol
    text = trivox.to_gismo_xml([column, vol]) if ext == ".xml" else trivox.to_g2([column, vol])
    reread = trivox.read_gismo_xml(text) if ext == ".xml" else trivox.read_g2(text)
    assert reread.volumes()[1] == vol


def _ulps_apart(a, b):
    """How many doubles lie between a and b (0: equal), elementwise."""
    ia = np.asarray(a, dtype=np.float64).view(np.int64)
    ib = np.asarray(b, dtype=np.float64).view(np.int64)
    # Same-signed doubles order as their bit patterns; the random points below keep their sign.
    return np.abs(ia - ib)


@pytest.mark.parametrize("ext", [".itd", ".g2", ".xml"])
def test_each_format_keeps_what_write_and_its_docstring_promise(tmp_path, ext):
    """write(), to_itd() and to_g2() promise: knots, weights and polynomial points the same
    doubles in every format, rational points too from .xml, and within an ulp from .itd and .g2
    (FORMATS.md). Random coordinates and weights from 1e-6 to 1e6, where w x rarely divides back."""
    rng = np.random.default_rng(11)
    kv = [0, 0, 0, 0.25, 1, 1, 1]
    pts = rng.uniform(1.0, 10.0, (64, 3)) * rng.choice([-1.0, 1.0], (64, 3))
    w = np.exp(rng.uniform(-6 * np.log(10), 6 * np.log(10), 64))
    rational = trivox.Spline([3, 3, 3], [kv] * 3, pts, w)
    polynomial = trivox.Spline([3, 3, 3], [kv] * 3, pts)
    path = tmp_path / ("round" + ext)
    trivox.write(path, [rational, polynomial])
    back = [p.spline for p in trivox.read(str(path)).patches]
    assert len(back) == 2
    assert back[1] == polynomial
    r = back[0]
    assert [k.tolist() for k in r.knots] == [k.tolist() for k in rational.knots]
    assert bits(r.weights) == bits(rational.weights)
    apart = _ulps_apart(r.points, rational.points)
    if ext == ".xml":
        assert apart.max() == 0
    else:
        assert apart.max() <= 1, apart.max()


def test_a_broken_spline_raises_model_error_naming_the_rule():
    with pytest.raises(trivox.ModelError, match="decrease"):
        trivox.Spline([2], [[0, 1, 0.5, 1]], [[0, 0, 0], [1, 1, 1]])
    with pytest.raises(ValueError, match="expected shape"):
        trivox.Spline([2, 2], [[0, 0, 1, 1], [0, 0, 1, 1]], np.zeros((5, 3)))
    with pytest.raises(trivox.ModelError):
        trivox.Volume(trivox.Spline([2, 2], [[0, 0, 1, 1], [0, 0, 1, 1]], np.zeros((4, 3))))
    with pytest.raises(ValueError, match="last axis has length 3"):
        trivox.read(str(ANNULUS)).volumes()[0].evaluate(np.zeros((4, 2)))


def test_arrays_outlive_their_volume_and_slicer(tmp_path):
    vol = trivox.Volume(annulus_spline())
    p = random_params(vol, 1000, 8)
    points, knots, x = vol.points, vol.knots, vol.evaluate(p)
    inv = vol.invert_global(x)
    expected = (points.copy(), [k.copy() for k in knots], x.copy(), inv.uvw.copy())
    scene = trivox.Scene(printer="j750-paper", materials=["VeroCyan"], cells=[trivox.Cell("VeroCyan", geometry=vol)])
    slicer = trivox.Slicer(scene)
    layer = slicer.slice_layer(slicer.layout.num_layers // 2, fractions=True, owner=True)
    labels = layer.labels.copy()
    del vol, scene, slicer
    gc.collect()
    # Fresh allocations that would reuse freed memory.
    junk = [np.full((1000, 3), 7.0) for _ in range(50)]
    assert (points == expected[0]).all() and all((a == b).all() for a, b in zip(knots, expected[1]))
    assert (x == expected[2]).all() and (inv.uvw == expected[3]).all()
    assert (layer.labels == labels).all() and layer.fractions.shape[:2] == labels.shape
    assert len(junk) == 50
