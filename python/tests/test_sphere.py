"""Sphere rules and spherical harmonics against closed forms."""
import numpy as np
import pytest

import skybake


@pytest.mark.parametrize("spec", ["lebedev:590", "design:10", "fibonacci:300", "mc:256"])
def test_weights_sum_to_one(spec):
    r = skybake.Rule(spec)
    assert len(r) == r.points.shape[0] == r.weights.shape[0]
    assert abs(r.weights.sum() - 1.0) < 1e-12
    np.testing.assert_allclose(np.linalg.norm(r.points, axis=1), 1.0, atol=1e-12)


def test_lebedev_integrates_polynomials():
    r = skybake.Rule("lebedev:590")  # precision 41
    assert r.precision == 41 and r.kind == "lebedev"
    x, y, z = r.points.T
    assert abs(np.dot(r.weights, z * z) - 1 / 3) < 1e-14
    assert abs(np.dot(r.weights, x**4) - 1 / 5) < 1e-14
    assert abs(np.dot(r.weights, x * x * y * y * z * z) - 1 / 105) < 1e-14


def test_sh_is_orthonormal():
    r = skybake.Rule("lebedev:590")
    order = 6
    y = skybake.sh_eval(order, np.ascontiguousarray(r.points))
    assert y.shape == (len(r), skybake.sh_count(order))
    gram = (y * (4 * np.pi * r.weights)[:, None]).T @ y
    np.testing.assert_allclose(gram, np.eye(skybake.sh_count(order)), atol=1e-12)
    assert skybake.sh_index(2, -1) == 5


def test_bad_rules_and_directions():
    with pytest.raises(skybake.Error):
        skybake.Rule("lebedev:591")
    with pytest.raises(skybake.Error, match="float64"):
        skybake.sh_eval(2, np.zeros((3, 3), np.float32))
    with pytest.raises(skybake.Error, match="order"):
        skybake.sh_eval(-1, np.zeros((3, 3)))
