"""The sky through Python: the reference model, the network, rendering and training."""
import numpy as np
import pytest

import skybake


@pytest.fixture(scope="module")
def earth():
    return skybake.atmosphere_preset("earth")


@pytest.fixture(scope="module")
def tiny_net(earth):
    # The seed's network exactly: its topology, inputs and outputs.
    return skybake.train_sky(earth, topology="paper", inputs="seed", outputs="radiance", brightness="linear",
                             samples=4000, adam_epochs=2, lm_iterations=1, seed=5)


def test_tables_agree_with_the_exact_quadrature(earth):
    samples = skybake.draw_sky_samples(400, seed=3)
    assert samples.shape == (400, 4) and samples.dtype == np.float32
    day = samples[(samples[:, 2] > 0.2) & (samples[:, 0] > 0.1)]
    tables = skybake.Sky.reference(earth).evaluate(np.ascontiguousarray(day))
    exact = skybake.Sky.reference(earth, method="exact").evaluate(np.ascontiguousarray(day))
    rel = np.linalg.norm(tables - exact, axis=1) / np.linalg.norm(exact, axis=1)
    assert np.median(rel) < 0.02 and np.max(rel) < 0.1


def test_the_noon_sky_is_blue_and_night_is_dark(earth):
    sky = skybake.Sky.reference(earth)
    # Straight up, the sun 60 degrees up: Rayleigh makes blue brightest.
    zenith = np.array([[1.0, np.cos(np.radians(30)), np.cos(np.radians(30)), 1.0]], np.float32)
    rgb = sky.evaluate(zenith)[0]
    assert rgb[2] > rgb[1] > rgb[0] > 0
    noon = sky.render(48, 48, sun_elevation_deg=60, sun_disc=False)
    night = sky.render(48, 48, sun_elevation_deg=-30, sun_disc=False)
    assert noon.shape == (48, 48, 3) and noon.dtype == np.float32
    assert night.mean() < 1e-3 * noon.mean()
    pano = sky.render(64, 32, view="panorama")
    assert pano.shape == (32, 64, 3)


def test_bad_samples(earth):
    sky = skybake.Sky.reference(earth)
    with pytest.raises(skybake.Error, match="4 entries"):
        sky.evaluate(np.zeros((3, 3), np.float32))
    with pytest.raises(skybake.Error, match="float32"):
        sky.evaluate(np.zeros((3, 4)))
    with pytest.raises(skybake.Error, match="not finite"):
        sky.evaluate(np.array([[np.nan, 1, 1, 1]], np.float32))
    impossible = np.array([[1.0, -1.0, 1.0, 1.0]], np.float32)  # V = U = L, but V·L = -1
    with pytest.raises(skybake.Error, match="row 0"):
        sky.evaluate(impossible)
    with pytest.raises(skybake.Error) as info:
        sky.render(8, 8, view="cubemap")
    assert info.value.where == "view"
    with pytest.raises(skybake.Error):
        skybake.atmosphere_preset("mars")


def test_network_round_trip(tiny_net, tmp):
    assert tiny_net.topology == "paper" and tiny_net.weight_count == 324
    assert tiny_net.weights.shape == (324,)
    path = tmp / "w.json"
    tiny_net.save(path)
    back = skybake.load_neural_sky(path)
    np.testing.assert_array_equal(back.weights, tiny_net.weights)
    samples = skybake.draw_sky_samples(100, seed=9)
    a = skybake.Sky.network(tiny_net).evaluate(samples)
    b = skybake.Sky.network(back).evaluate(samples)
    np.testing.assert_array_equal(a, b)
    assert "skybake_sky" in tiny_net.export("glsl")
    assert "highp vec3 skybake_sky(" in tiny_net.export("glsl-es")
    path.write_text("{\"format\": \"skybake-neural-sky\", \"version\": 1}")
    with pytest.raises(skybake.Error):
        skybake.load_neural_sky(path)


def test_an_aerosol_family_takes_its_amount_at_run_time(earth):
    net = skybake.train_sky(earth, samples=4000, adam_epochs=2, lm_iterations=0, seed=3, aerosol_range=(1.0, 16.0))
    again = skybake.train_sky(earth, samples=4000, adam_epochs=2, lm_iterations=0, seed=3, aerosol_range=(1.0, 16.0))
    np.testing.assert_array_equal(again.weights, net.weights)
    assert net.aerosol_range == (1.0, 16.0) and net.aerosol == 1.0
    samples = skybake.draw_sky_samples(200, seed=4)
    clear = skybake.Sky.network(net).evaluate(samples)
    net.aerosol = 12.0
    hazy = skybake.Sky.network(net).evaluate(samples)
    assert np.abs(hazy - clear).max() > 0.0
    assert "float aerosol" in net.export("c")
    with pytest.raises(skybake.Error, match="aerosol"):
        net.aerosol = 20.0
    assert net.aerosol == 12.0
    plain = skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0)
    assert plain.aerosol_range is None
    hard = skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0, hard_share=0.3)
    assert np.abs(hard.weights - plain.weights).max() > 0.0
    with pytest.raises(skybake.Error, match="hard"):
        skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0, hard_share=2.0)
    with pytest.raises(skybake.Error, match="flight_share"):
        skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0, flight_share=1.5)
    with pytest.raises(skybake.Error, match="multiple_term"):
        skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0, multiple_term="cubic")
    flown = skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0, flight_share=0.5)
    assert np.abs(flown.weights - plain.weights).max() > 0.0
    with pytest.raises(skybake.Error, match="aerosol"):
        plain.aerosol = 2.0


def test_training_is_deterministic(earth, tiny_net):
    again = skybake.train_sky(earth, topology="paper", inputs="seed", outputs="radiance", brightness="linear",
                              samples=4000, adam_epochs=2, lm_iterations=1, seed=5)
    np.testing.assert_array_equal(again.weights, tiny_net.weights)
    assert (tiny_net.inputs, tiny_net.outputs) == ("seed", "radiance")
    events = []
    default = skybake.train_sky(earth, samples=2000, adam_epochs=1, lm_iterations=0, progress=events.append)
    assert events and events[-1].finished
    # The default: the best small network, horizon inputs and residual
    # outputs (Rayleigh and Mie, three channels each).
    assert (default.topology, default.inputs, default.outputs) == ("shared:16x12", "horizon", "residual")
    assert default.weight_count == (4 + 1) * 16 + (16 + 1) * 12 + (12 + 1) * 6
    with pytest.raises(skybake.Error, match="outputs"):
        skybake.train_sky(earth, outputs="spectral", samples=2000, adam_epochs=1, lm_iterations=0)


def test_atmosphere_json_round_trip(earth):
    text = earth.to_json()
    back = skybake.Atmosphere.from_json(text)
    assert back.to_json() == text and back.name == earth.name
    assert back.components[0] == "rayleigh"
    with pytest.raises(skybake.Error):
        skybake.Atmosphere.from_json("{")


def test_image_files(tmp):
    img = np.linspace(0, 1, 4 * 6 * 3, dtype=np.float32).reshape(4, 6, 3)
    skybake.save_image(tmp / "a.exr", img)
    np.testing.assert_allclose(skybake.load_image(tmp / "a.exr"), img, rtol=1e-3, atol=1e-3)  # half floats
    skybake.save_image(tmp / "a.png", img, tone="clamp")
    png = skybake.load_image(tmp / "a.png")
    assert png.shape == (4, 6, 3)
    np.testing.assert_allclose(png, img, atol=0.01)


def test_multiple_scattering_tables_come_from_the_cache(earth, tmp_path, monkeypatch):
    # The module reads the same on-disk cache as the CLI (docs/sky.md), so the
    # Blender add-on's skies with multiple scattering pay for their tables once.
    import json
    cache = tmp_path / "cache"
    monkeypatch.setenv("SKYBAKE_CACHE_DIR", str(cache))
    spec = json.loads(earth.to_json())
    spec.update(scattering="multiple", multiple_method="hillaire")
    atmosphere = skybake.Atmosphere.from_json(json.dumps(spec))
    samples = np.ascontiguousarray(skybake.draw_sky_samples(64, seed=4))
    first = skybake.Sky.reference(atmosphere).evaluate(samples)
    files = sorted(p.name for p in cache.iterdir())
    assert len(files) == 1 and files[0].startswith("multiple-scattering-")
    second = skybake.Sky.reference(atmosphere).evaluate(samples)
    assert np.array_equal(first, second)
    # A damaged file is recomputed: the same answer, the file whole again.
    path = cache / files[0]
    whole = path.read_bytes()
    path.write_bytes(whole[: len(whole) // 2])
    assert np.array_equal(skybake.Sky.reference(atmosphere).evaluate(samples), first)
    assert path.read_bytes() == whole
    monkeypatch.setenv("SKYBAKE_CACHE_DIR", "off")
    assert np.array_equal(skybake.Sky.reference(atmosphere).evaluate(samples), first)
