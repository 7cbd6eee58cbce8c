"""Meshes: arrays in and out, files, and the errors for bad arrays."""
import numpy as np
import pytest

import skybake

TRIANGLE = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
ONE = np.array([[0, 1, 2]], np.uint32)


def test_arrays_round_trip():
    normals = np.tile(np.array([0, 0, 1], np.float32), (3, 1))
    colors = np.array([[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 0.5]], np.float32)
    m = skybake.Mesh(TRIANGLE, ONE, normals=normals, colors=colors)
    assert m.vertex_count == 3 and m.triangle_count == 1
    np.testing.assert_array_equal(m.positions, TRIANGLE)
    np.testing.assert_array_equal(m.indices, ONE)
    np.testing.assert_array_equal(m.normals, normals)
    np.testing.assert_array_equal(m.colors, colors)
    assert m.positions.dtype == np.float32 and m.indices.dtype == np.uint32


def test_properties_are_copies():
    m = skybake.Mesh(TRIANGLE, ONE)
    p = m.positions
    p[0, 0] = 42.0
    assert m.positions[0, 0] == 0.0
    m.positions = p
    assert m.positions[0, 0] == 42.0


def test_attributes_round_trip():
    m = skybake.Mesh(TRIANGLE, ONE)
    m.set_attribute("ao", np.array([0.25, 0.5, 1.0], np.float32))
    m.set_attribute("bent_normal", np.eye(3, dtype=np.float32))
    assert set(m.attribute_names) == {"ao", "bent_normal"}
    np.testing.assert_array_equal(m.attribute("ao"), [0.25, 0.5, 1.0])
    np.testing.assert_array_equal(m.attribute("bent_normal"), np.eye(3))
    with pytest.raises(skybake.Error, match="no attribute"):
        m.attribute("nope")


@pytest.mark.parametrize("ext", [".ply", ".glb"])
def test_file_round_trip(tmp, ext):
    m = skybake.generate_mesh("torus", 500)
    m.compute_normals()
    m.set_attribute("ao", np.linspace(0, 1, m.vertex_count, dtype=np.float32))
    path = tmp / ("torus" + ext)
    skybake.save_mesh(path, m)
    back = skybake.load_mesh(path)
    assert back.vertex_count == m.vertex_count and back.triangle_count == m.triangle_count
    np.testing.assert_array_equal(back.positions, m.positions)
    np.testing.assert_array_equal(back.indices, m.indices)
    np.testing.assert_allclose(back.attribute("ao"), m.attribute("ao"), atol=0)


def test_generate_is_deterministic():
    a = skybake.generate_mesh("city", 3000, seed=7)
    b = skybake.generate_mesh("city", 3000, seed=7)
    c = skybake.generate_mesh("city", 3000, seed=8)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert a.vertex_count != c.vertex_count or not np.array_equal(a.positions, c.positions)
    assert "bowl" in skybake.procedural_kinds()


def test_bounds_of_unit_sphere(sphere):
    lo, hi = sphere.bounds()
    np.testing.assert_allclose(lo, [-1, -1, -1], atol=1e-6)
    np.testing.assert_allclose(hi, [1, 1, 1], atol=1e-6)


@pytest.mark.parametrize(
    "positions, indices, where, message",
    [
        (TRIANGLE.astype(np.float64), ONE, "positions", "dtype float32, got float64"),
        (TRIANGLE, ONE.astype(np.int64), "indices", "dtype uint32, got int64"),
        (TRIANGLE[:, :2].copy(), ONE, "positions", "3 entries along axis 1"),
        (TRIANGLE.ravel(), ONE, "positions", "shape"),
        (np.asfortranarray(np.tile(TRIANGLE, (2, 1))), ONE, "positions", "not C-contiguous"),
        (TRIANGLE[::-1], ONE, "positions", "not C-contiguous"),
        (np.array([[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]], np.float32), ONE, "positions", "not finite"),
        (TRIANGLE, np.array([[0, 1, 3]], np.uint32), "mesh", "uses vertex index 3"),
        (TRIANGLE.tolist(), ONE, "positions", "NumPy array"),
    ],
)
def test_bad_arrays(positions, indices, where, message):
    with pytest.raises(skybake.Error, match=message) as info:
        skybake.Mesh(positions, indices)
    assert isinstance(info.value, RuntimeError)
    assert info.value.where == where, info.value


def test_missing_and_broken_files(tmp):
    with pytest.raises(skybake.Error) as info:
        skybake.load_mesh(tmp / "missing.ply")
    assert "missing.ply" in str(info.value)
    bad = tmp / "bad.ply"
    bad.write_bytes(b"ply\nformat binary_little_endian 1.0\nelement vertex 99\nproperty float x\nend_header\n\x00")
    with pytest.raises(skybake.Error):
        skybake.load_mesh(bad)
    with pytest.raises(skybake.Error, match="cannot write"):
        skybake.save_mesh(tmp / "out.xyz", skybake.Mesh(TRIANGLE, ONE))
    assert not (tmp / "out.xyz").exists()


def test_nan_and_negative_values_raise(tmp_path):
    # docs/python.md: a NaN raises, naming the argument; nothing is written.
    m = skybake.Mesh(TRIANGLE, ONE)
    for bad in (np.array([0.5, np.nan, 0.5], np.float32), np.array([0.5, np.inf, 0.5], np.float32)):
        with pytest.raises(skybake.Error) as info:
            m.set_attribute("ao", bad)
        assert info.value.where == "values"
    with pytest.raises(skybake.Error) as info:
        m.set_attribute("bent", np.full((3, 3), np.nan, np.float32))
    assert info.value.where == "values"
    img = np.zeros((4, 4, 3), np.float32)
    img[1, 2, 0] = np.nan
    for name in ("a.png", "a.exr"):
        with pytest.raises(skybake.Error) as info:
            skybake.save_image(tmp_path / name, img)
        assert info.value.where == "rgb"
        assert not (tmp_path / name).exists()
    with pytest.raises(skybake.Error) as info:
        skybake.set_threads(-1)
    assert info.value.where == "count"
    skybake.set_threads(0)
    assert skybake.threads() >= 1
