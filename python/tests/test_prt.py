"""PRT through Python: the transfer bake, SH lights, relighting and the asset files."""
import numpy as np
import pytest

import skybake


def test_constant_light_gives_albedo_times_ao(bowl):
    m = bowl.copy()
    ao = skybake.bake_ao(m.copy(), rule="lebedev:590").ao
    t = skybake.bake_transfer(m, rule="lebedev:590", order=2)
    assert t.coeffs.shape == (m.vertex_count, 1, 9)
    # The shadowed transfer's first coefficient is AO / (2√π).
    np.testing.assert_allclose(t.coeffs[:, 0, 0] * 2 * np.sqrt(np.pi), ao, atol=2e-6)
    light = skybake.constant_light([1.0, 0.5, 0.25], order=2)
    albedo = np.full((m.vertex_count, 3), 0.8, np.float32)
    b = skybake.relight(t, light, albedo)
    expected = 0.8 * ao[:, None] * np.array([1.0, 0.5, 0.25])
    np.testing.assert_allclose(b, expected, atol=1e-5)


def test_sky_light_and_sun(bowl):
    sky = skybake.Sky.reference(skybake.atmosphere_preset("earth"))
    light = skybake.sky_light(sky, sun_elevation_deg=40, sun_azimuth_deg=90, order=3, rule="lebedev:590")
    assert light.coeffs.shape == (16, 3)
    sun = np.array(light.sun_direction)
    np.testing.assert_allclose(sun, skybake.sun_direction(40, 90), atol=1e-6)
    assert sun[0] > 0.7 and sun[1] > 0.6  # azimuth 90: towards +x
    assert min(light.sun_irradiance) > 0
    down = skybake.sky_light(sky, sun_elevation_deg=-30, order=3, rule="lebedev:590")
    assert max(down.sun_irradiance) == 0
    # The lit ground (as `sky sh --ground-albedo`): brighter below, L_1,-1 (∝ y) lower; refused outside [0, 1].
    ground = skybake.sky_light(sky, sun_elevation_deg=40, sun_azimuth_deg=90, order=3, rule="lebedev:590",
                               ground_albedo=[0.3])
    assert np.all(ground.coeffs[0] > light.coeffs[0]) and np.all(ground.coeffs[1] < light.coeffs[1])
    with pytest.raises(skybake.Error, match="ground_albedo"):
        skybake.sky_light(sky, ground_albedo=[1.5])
    with pytest.raises(skybake.Error, match="ground_albedo"):
        skybake.sky_light(sky, ground_albedo=[0.1, float("nan"), 0.1])
    m = bowl.copy()
    t = skybake.bake_transfer(m, order=3)
    albedo = np.full((m.vertex_count, 3), 0.5, np.float32)
    vis = skybake.sun_visibility(m, light.sun_direction)
    assert vis.shape == (m.vertex_count,) and set(np.unique(vis)) <= {0.0, 1.0}
    lit = skybake.relight(t, light, albedo, m.normals, vis)
    sky_only = skybake.relight(t, light, albedo)
    assert np.all(lit >= sky_only - 1e-7) and lit.mean() > sky_only.mean()
    with pytest.raises(skybake.Error, match="both"):
        skybake.relight(t, light, albedo, normals=m.normals)
    with pytest.raises(skybake.Error) as info:
        skybake.relight(t, light, albedo[:5])
    assert info.value.where == "albedo"


def test_equirect_light_of_a_constant_map():
    env = np.full((32, 64, 3), 0.25, np.float32)
    light = skybake.equirect_light(env, order=2)
    assert abs(light.coeffs[0, 0] - 0.25 * 2 * np.sqrt(np.pi)) < 1e-4
    assert np.max(np.abs(light.coeffs[1:])) < 1e-4


def test_asset_round_trip(tmp, sphere):
    m = sphere.copy()
    t = skybake.bake_transfer(m, order=3)
    path = tmp / "baked.glb"
    skybake.save_prt(path, m, t)
    assert (tmp / "baked.prt.json").exists()
    mesh, back, albedo = skybake.load_prt(path)
    assert back.order == 3 and back.kind == "shadowed"
    np.testing.assert_array_equal(back.coeffs, t.coeffs)
    assert albedo.shape == (m.vertex_count, 3)
    (tmp / "baked.prt.json").write_text("{}")
    with pytest.raises(skybake.Error) as info:
        skybake.load_prt(path)
    assert info.value.where == "sidecar"
    assert "skybake_prt_diffuse" in skybake.export_prt_glsl(3)
    es = skybake.export_prt_glsl(3, es=True)
    assert "highp vec3 skybake_prt_diffuse(" in es and "precision highp float;" in es
