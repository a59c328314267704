"""The Python module against the command line, and its refusals."""
import resource

import numpy as np
import pytest

import bendlab

ALL_METHODS = bendlab.methods() if hasattr(bendlab, "methods") else ["A", "B", "C", "D", "E", "ED"]


@pytest.fixture(scope="module")
def rbc_1280(tmp_path_factory, cli):
    path = tmp_path_factory.mktemp("mesh") / "rbc.off"
    cli("mesh", "--family", "mt1", "--level", "3", "--shape", "rbc", "--out", path)
    return path


def method_names():
    return [m["name"] if isinstance(m, dict) else m for m in ALL_METHODS]


@pytest.mark.parametrize("name", method_names())
def test_every_method_equals_the_cli(name, rbc_1280, cli, tmp_path):
    out = tmp_path / "f.csv"
    cli("forces", "--mesh", rbc_1280, "--method", name, "--out", out)
    table = np.genfromtxt(out, delimiter=",", names=True)
    mesh = bendlab.read_mesh(rbc_1280)
    assert mesh.num_faces == 1280
    r = bendlab.Method(name).compute(mesh, kappa_b=1.0)
    # The CSV carries 17 significant digits: the same doubles, compared exactly (NaN == NaN).
    for col, got in [("H", r.H), ("K", r.K), ("lapH", r.lapH), ("area", r.area)]:
        np.testing.assert_array_equal(table[col], got, err_msg=f"{name} {col}")
    for cols, got in [(("fx", "fy", "fz"), r.force_density), (("Fx", "Fy", "Fz"), r.force),
                      (("nx", "ny", "nz"), r.normal)]:
        np.testing.assert_array_equal(np.column_stack([table[c] for c in cols]), got, err_msg=f"{name} {cols}")
    np.testing.assert_array_equal(bendlab.Method(name).forces(mesh), r.force)


def test_results_are_read_only_views_of_the_library_arrays():
    mesh = bendlab.sphere_mesh("mt1", 2)
    r = bendlab.Method("B").compute(mesh)
    assert r.H.base is not None and not r.H.flags.writeable
    assert r.force.shape == (mesh.num_vertices, 3) and r.force.flags.c_contiguous
    with pytest.raises(ValueError):
        r.H[0] = 1.0
    # forces() hands over a new array the caller owns.
    f = bendlab.Method("B").forces(mesh)
    assert f.flags.writeable
    f[0, 0] = 0.0


def test_energy_based_methods_give_the_sphere_energy():
    mesh = bendlab.sphere_mesh("mt1", 4)
    energy = bendlab.Method("B").energy(mesh, kappa_b=2.0)
    assert energy == pytest.approx(8 * np.pi * 2.0, rel=2e-3)
    assert bendlab.Method("C").energy(mesh) is None


def test_static_errors_match_the_study_measures():
    mesh = bendlab.sphere_mesh("mt1", 3)
    rbc = bendlab.surface("rbc")
    mesh = mesh.with_positions(rbc.map_from_unit_sphere(mesh.vertices))
    r = bendlab.Method("E").compute(mesh)
    errors = bendlab.node_errors(rbc, mesh.vertices, r)
    assert set(errors) == {"n", "H", "K", "lapH", "f"}
    exact = rbc.evaluate(mesh.vertices)
    np.testing.assert_allclose(errors["H"], np.abs(exact["H"] - r.H) / rbc.maxima()["H"], rtol=1e-14, atol=0)
    s = bendlab.summarize(errors["H"])
    assert s["max"] == errors["H"].max() and s["average"] == pytest.approx(errors["H"].mean(), rel=1e-14)
    # Nodes of a sphere are not on the RBC: refused, naming a node.
    with pytest.raises(ValueError, match="node"):
        bendlab.node_errors(rbc, bendlab.sphere_mesh("mt1", 3).vertices, r)


@pytest.mark.parametrize("bad, message", [
    (lambda v, f: (v[:, :2], f), "shape"),
    (lambda v, f: (v.astype(np.float32), f), "float64"),
    (lambda v, f: (np.asfortranarray(v), f), "C-contiguous"),
    (lambda v, f: (v[::2], f), "C-contiguous"),
    (lambda v, f: (np.where(np.arange(len(v))[:, None] == 3, np.nan, v), f), "not finite"),
    (lambda v, f: (v, f + len(v)), "out of range"),
    (lambda v, f: (v, np.abs(f) * -1 - 1), "outside"),
    (lambda v, f: (v, f.astype(float)), "integer"),
    (lambda v, f: (v, f[:-1]), "open"),
    (lambda v, f: (v.tolist(), f), "numpy array"),
])
def test_bad_arrays_raise_value_error_with_the_library_message(bad, message):
    mesh = bendlab.sphere_mesh("mt1", 1)
    v, f = np.array(mesh.vertices), np.array(mesh.faces)
    with pytest.raises(ValueError, match=message):
        bendlab.Mesh(*bad(v, f))


def test_bad_method_names_and_options_raise_value_error():
    with pytest.raises(ValueError, match="unknown"):
        bendlab.Method("Z")
    with pytest.raises(ValueError, match="rings"):
        bendlab.Method("E", rings=7)
    with pytest.raises(ValueError):
        bendlab.Method("C").compute(bendlab.sphere_mesh("mt1", 1), kappa_b=float("nan"))
    with pytest.raises(ValueError, match="rows"):
        bendlab.sphere_mesh("mt1", 1).with_positions(np.zeros((3, 3)))


def test_the_module_applies_the_command_lines_checks():
    # kappa_b = 1e308 overflows the forces: refused like `bendlab forces`, naming the quantity.
    with pytest.raises(ValueError, match="not finite"):
        bendlab.Method("C").compute(bendlab.sphere_mesh("mt1", 1), kappa_b=1e308)
    with pytest.raises(ValueError, match="not finite"):
        bendlab.Method("C").forces(bendlab.sphere_mesh("mt1", 1), kappa_b=1e308)
    # The mesh sizes of `bendlab mesh --level 0..8 --rivara 0..6`.
    with pytest.raises(ValueError, match="level must be 0..8"):
        bendlab.sphere_mesh("mt1", level=9)
    with pytest.raises(ValueError, match="rivara_passes must be 0..6"):
        bendlab.sphere_mesh("mt1", level=1, rivara_passes=50)


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * resource.getpagesize()


def test_ten_thousand_calls_leave_the_resident_memory_bounded():
    mesh = bendlab.sphere_mesh("mt1", 2)
    method = bendlab.Method("C")
    # Two library calls per iteration: 10^4 calls in the measured loop.

    def calls(n):
        for _ in range(n):
            r = method.compute(mesh)
            _ = r.force_density.sum() + method.forces(mesh).sum()

    calls(500)  # warm up allocator pools
    before = rss_bytes()
    calls(5000)
    grown = rss_bytes() - before
    # Each compute() allocates about 60 kB of results; a leak of one result per call would grow the
    # process by 300 MB. Allow allocator noise of a few MB.
    assert grown < 8 * 2**20, f"resident memory grew by {grown / 2**20:.1f} MiB over 10^4 calls"


@pytest.mark.parametrize("name", ["B", "C", "J"])
def test_membrane_parameters_equal_the_cli(name, rbc_1280, cli, tmp_path):
    # c0 and ADE (docs/conventions.md §5): the same doubles as `bendlab forces --c0 ... --ade-*`.
    out = tmp_path / "f.csv"
    cli("forces", "--mesh", rbc_1280, "--method", name, "--c0", "0.75", "--ade-alpha", "2", "--ade-d", "0.02",
        "--ade-da0", "0.1", "--ade-area", "8.4", "--out", out)
    table = np.genfromtxt(out, delimiter=",", names=True)
    mesh = bendlab.read_mesh(rbc_1280)
    m = bendlab.Method(name, c0=0.75, ade_alpha=2, ade_d=0.02, ade_da0=0.1, ade_area=8.4)
    r = m.compute(mesh)
    np.testing.assert_array_equal(np.column_stack([table[c] for c in ("Fx", "Fy", "Fz")]), r.force)
    np.testing.assert_array_equal(m.forces(mesh), r.force)
    # The plain method differs, and c0 = 0 without ADE is the plain method exactly.
    assert not np.array_equal(bendlab.Method(name).forces(mesh), r.force)
    np.testing.assert_array_equal(bendlab.Method(name, c0=0.0).forces(mesh), bendlab.Method(name).forces(mesh))


@pytest.mark.parametrize("key", ["c0", "ade_alpha", "ade_d", "ade_da0", "ade_area"])
@pytest.mark.parametrize("value", [None, "1", 1j, [1.0]])
def test_a_membrane_parameter_that_is_no_real_number_is_named(key, value):
    with pytest.raises(TypeError, match=rf"Method: {key} must be a real number, got .* \({type(value).__name__}\)$"):
        bendlab.Method("C", **{key: value})


def test_membrane_parameters_are_refused_where_invalid():
    with pytest.raises(ValueError, match="method A"):
        bendlab.Method("A", c0=1.0)
    with pytest.raises(ValueError, match="ade_area"):
        bendlab.Method("C", ade_alpha=1.0, ade_d=0.1)
    with pytest.raises(ValueError, match="finite"):
        bendlab.Method("C", c0=float("nan"))
