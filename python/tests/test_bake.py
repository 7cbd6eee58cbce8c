"""Bakes through Python: closed forms, the CLI on the same mesh, the bits,
progress, the GIL and Ctrl-C."""
import json
import os
import pathlib
import struct
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import skybake


def test_bowl_ao_is_one_half(bowl):
    # Any point inside a hemispherical bowl sees the opening as half its
    # cosine-weighted hemisphere (the sphere's form factor is the area ratio).
    m = bowl.copy()
    r = skybake.bake_ao(m, rule="lebedev:5810")
    y = m.positions[:, 1]
    inner = y < -0.2  # away from the rim, whose vertices see past it
    assert inner.sum() > 100
    assert np.max(np.abs(r.ao[inner] - 0.5)) < 0.02
    assert abs(np.median(r.ao[inner]) - 0.5) < 5e-3


def test_convex_mesh_sees_everything(sphere):
    m = sphere.copy()
    r = skybake.bake_ao(m, rule="lebedev:590")
    assert r.ao.shape == (m.vertex_count,) and r.ao.dtype == np.float32
    assert np.min(r.ao) > 0.998 and np.min(r.shading) > 0.998  # the rule's error for the clamped cosine
    n = skybake.bake_ao(m.copy(), rule="lebedev:590", normalize=True)
    assert np.min(n.ao) > 1 - 1e-6 and np.min(n.shading) > 1 - 1e-6
    # The bent normal of an unoccluded vertex is its normal.
    dots = np.einsum("ij,ij->i", r.bent_normal, m.normals)
    assert np.min(dots) > 0.9999


def test_results_are_stored_on_the_mesh(bowl):
    m = bowl.copy()
    r = skybake.bake_ao(m)
    np.testing.assert_array_equal(m.attribute("ao"), r.ao)
    np.testing.assert_array_equal(m.attribute("shading"), r.shading)
    np.testing.assert_array_equal(m.attribute("bent_normal"), r.bent_normal)
    np.testing.assert_array_equal(m.colors[:, 0], r.ao)


@pytest.mark.parametrize("options", [{}, {"max_distance": 0.3, "back_faces": "ignore", "offset": 0.001}])
def test_same_as_the_cli(cli, tmp, options):
    m = skybake.generate_mesh("city", 4000, seed=3)
    m.compute_normals()
    src = tmp / "city.ply"
    skybake.save_mesh(src, m)
    r = skybake.bake_ao(m, rule="lebedev:230", **options)
    flags = []
    if "max_distance" in options:
        flags += ["--max-distance", options["max_distance"], "--back-faces", options["back_faces"],
                  "--offset", options["offset"]]
    cli("ao", src, "-o", tmp / "out.ply", "--rule", "lebedev:230", "--quiet", *flags)
    out = skybake.load_mesh(tmp / "out.ply")
    assert np.max(np.abs(out.attribute("ao") - r.ao)) <= 1e-6
    assert np.max(np.abs(out.attribute("shading") - r.shading)) <= 1e-6
    assert np.max(np.abs(out.attribute("bent_normal") - r.bent_normal)) <= 1e-6


def test_bits_reproduce_the_ao(bowl):
    m = bowl.copy()
    rule = skybake.Rule("lebedev:590")
    r = skybake.bake_ao(m, rule=rule.spec, store_bits=True)
    assert r.bits.dtype == np.uint32 and r.bits.shape == (m.vertex_count, (len(rule) + 31) // 32)
    k = np.arange(len(rule))
    visible = (r.bits[:, k // 32] >> (k % 32).astype(np.uint32)) & 1
    cos = np.clip(m.normals.astype(np.float64) @ rule.points.T, 0, None)
    ao = np.clip((visible * cos * 4 * rule.weights).sum(axis=1), 0, 1)
    assert np.max(np.abs(ao - r.ao)) < 1e-5


def test_brute_force_agrees_with_embree():
    m = skybake.generate_mesh("wall", 800)
    a = skybake.bake_ao(m.copy(), rule="lebedev:230", backend="embree", store_bits=True)
    b = skybake.bake_ao(m.copy(), rule="lebedev:230", backend="brute", store_bits=True)
    same = np.mean(a.bits == b.bits)
    assert same > 0.99
    assert np.max(np.abs(a.ao - b.ao)) < 0.05


def test_backends_and_bad_options(bowl):
    names = [b.name for b in skybake.backends()]
    assert {"embree", "brute", "raster"} <= set(names)
    assert all(b.available or b.problem for b in skybake.backends())
    with pytest.raises(skybake.Error) as info:
        skybake.bake_ao(bowl.copy(), backend="optix")
    assert info.value.where == "backend"
    with pytest.raises(skybake.Error) as info:
        skybake.bake_ao(bowl.copy(), max_distance=-1)
    assert info.value.where == "max_distance"
    with pytest.raises(skybake.Error):
        skybake.bake_ao(bowl.copy(), rule="nope:1")
    with pytest.raises(skybake.Error) as info:
        skybake.bake_ao(bowl.copy(), backend="embree", method="cube")
    assert info.value.where == "method"
    # Beyond the tracers' range (Embree aborts past 1.8e18): refused, the interpreter lives.
    for offset in (1e20, 2e18, 1e40, float("inf")):
        with pytest.raises(skybake.Error) as info:
            skybake.bake_ao(bowl.copy(), offset=offset)
        assert info.value.where == "offset"
    far = bowl.copy()
    far.positions = far.positions * np.float32(1e19)
    with pytest.raises(skybake.Error, match="coordinate reaches") as info:
        skybake.bake_ao(far)
    assert info.value.where == "mesh"


def test_empty_mesh_is_an_error():
    with pytest.raises(skybake.Error, match="no triangles"):
        skybake.Mesh(np.zeros((0, 3), np.float32), np.zeros((0, 3), np.uint32))
    m = skybake.generate_mesh("sphere", 200)
    m.indices = np.zeros((0, 3), np.uint32)  # emptied after construction
    with pytest.raises(skybake.Error, match="no triangles"):
        skybake.bake_ao(m)


def test_progress_callback_sees_the_end(bowl):
    events = []
    skybake.bake_ao(bowl.copy(), rule="lebedev:590", progress=events.append)
    assert events and events[-1].finished and events[-1].label == "bake"
    assert events[-1].done == events[-1].total == bowl.vertex_count
    assert all(0.0 <= e.fraction <= 1.0 for e in events)


def big_bake():
    return skybake.generate_mesh("city", 20000, seed=2), "lebedev:2030"


def test_an_exception_in_the_callback_stops_the_bake():
    m, rule = big_bake()

    class Stop(Exception):
        pass

    calls = []

    def progress(e):
        calls.append(e.done)
        raise Stop("enough")

    t0 = time.perf_counter()
    with pytest.raises(Stop, match="enough"):
        skybake.bake_ao(m, rule=rule, progress=progress)
    assert len(calls) == 1
    assert "ao" not in m.attribute_names  # nothing stored
    with pytest.raises(skybake.Error, match="callable"):
        skybake.bake_ao(m, progress=42)
    assert time.perf_counter() - t0 < 60


def test_the_gil_is_released_during_a_bake():
    m, rule = big_bake()
    ticks = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks[0] += 1
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.05)
    before = ticks[0]
    t0 = time.perf_counter()
    skybake.bake_ao(m, rule=rule)
    seconds = time.perf_counter() - t0
    during = ticks[0] - before
    stop.set()
    t.join()
    assert seconds > 0.2, "the bake is too short to tell"
    # Holding the GIL for the bake would stop the counter (0 or 1 tick);
    # released, it ticks every millisecond or so, fewer on a loaded machine.
    assert during >= 10, (during, seconds)


def test_ctrl_c_raises_keyboard_interrupt():
    m, rule = big_bake()
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    t0 = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        skybake.bake_ao(m, rule=rule)
        time.sleep(5)  # a bake that finished first: the signal arrives here
    timer.join()
    assert time.perf_counter() - t0 < 30
    # Python's handler is back: the next call runs normally.
    skybake.bake_ao(skybake.generate_mesh("sphere", 200))


def run_child(code, timeout=120):
    """Runs `code` in a fresh interpreter with this module; returns the process."""
    return subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=dict(os.environ))


INTERRUPTED_CALLS = """
    import sys, skybake
    m = skybake.generate_mesh("city", 20000, seed=2)
    sky = skybake.Sky.reference(skybake.atmosphere_preset("earth"))
    calls = {
        "bake_ao": lambda: skybake.bake_ao(m.copy(), rule="lebedev:5810"),
        "render": lambda: sky.render(4096, 2048, view="panorama"),
        "bake_transfer": lambda: skybake.bake_transfer(m.copy(), rule="lebedev:5810"),
        "raster": lambda: skybake.bake_ao(m.copy(), rule="lebedev:5810", backend="raster", resolution=512),
    }
    for name in sys.argv[1:]:
        print("go", name, flush=True)
        try:
            calls[name]()
            print("finished", name, flush=True)
        except KeyboardInterrupt:
            print("KeyboardInterrupt", name, flush=True)
"""


def test_every_ctrl_c_stops_a_long_call():
    # One Ctrl-C per call, call after call: each must raise KeyboardInterrupt
    # within seconds (each call alone runs for minutes on two cores).
    names = ["bake_ao", "render", "bake_ao", "bake_transfer", "render"]
    raster = [b for b in skybake.backends() if b.name == "raster"][0]
    if raster.available:  # its passes poll the library's flag, not the progress steps
        names += ["raster", "bake_ao", "raster"]
    p = subprocess.Popen([sys.executable, "-c", textwrap.dedent(INTERRUPTED_CALLS), *names],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    watchdog = threading.Timer(60 + 20 * len(names), p.kill)
    watchdog.start()
    try:
        seen = []
        for line in p.stdout:
            word, name = line.split()
            if word == "go":
                time.sleep(0.5)
                t0 = time.perf_counter()
                os.kill(p.pid, signal.SIGINT)
            else:
                seen.append((word, name, time.perf_counter() - t0))
        p.wait()
    finally:
        watchdog.cancel()
    assert p.returncode == 0, p.stderr.read()
    assert [(w, n) for w, n, _ in seen] == [("KeyboardInterrupt", n) for n in names], seen
    assert max(s for _, _, s in seen) < 20, seen


def test_ctrl_c_while_the_result_is_handed_back_raises():
    # The signal comes after the bake's last step, while the call waits for the
    # GIL to return its result (another thread holds it): KeyboardInterrupt
    # follows the result instead of being dropped with the call's handler.
    p = run_child("""
        import os, signal, sys, threading, time, skybake
        sys.setswitchinterval(1000)  # the spinning thread keeps the GIL until it ends
        m = skybake.generate_mesh("city", 1000, seed=2)
        def hold_the_gil():
            time.sleep(0.01)  # wakes up during the bake, which released the GIL
            end = time.perf_counter() + 0.5
            while time.perf_counter() < end:  # the bake (~0.1 s) ends meanwhile
                pass
            os.kill(os.getpid(), signal.SIGINT)
        t = threading.Thread(target=hold_the_gil)
        try:
            t.start()
            t0 = time.perf_counter()
            skybake.bake_ao(m, rule="lebedev:590")
            print("returned after", time.perf_counter() - t0, flush=True)
            time.sleep(3)
            print("lost")
        except KeyboardInterrupt:
            print("KeyboardInterrupt")
        t.join()
    """)
    out, err = p.communicate(timeout=60)
    assert p.returncode == 0, err
    assert out.splitlines()[-1] == "KeyboardInterrupt", out


def test_preview_shows_the_values(bowl):
    m = bowl.copy()
    img = skybake.render_preview(m, np.full(m.vertex_count, 0.5, np.float32), width=64, height=48, samples=1)
    assert img.shape == (48, 64, 3)
    covered = np.all(np.abs(img - 0.5) < 1e-6, axis=2)
    assert 0.1 < covered.mean() < 0.9  # the bowl, and the background around it
    red = skybake.render_preview(m, np.tile(np.array([1, 0, 0], np.float32), (m.vertex_count, 1)), 64, 48, samples=1)
    np.testing.assert_allclose(red[covered], np.tile([1.0, 0.0, 0.0], (covered.sum(), 1)), atol=1e-6)
    with pytest.raises(skybake.Error) as info:
        skybake.render_preview(m, np.zeros(3, np.float32))
    assert info.value.where == "values"


def test_raster_backend_bakes_the_bowl(bowl):
    raster = [b for b in skybake.backends() if b.name == "raster"][0]
    if not raster.available:
        pytest.skip("no headless OpenGL: " + raster.problem)
    m = bowl.copy()
    r = skybake.bake_ao(m, rule="lebedev:590", backend="raster", resolution=128)
    assert r.backend == "raster" and r.method == "cube"
    inner = m.positions[:, 1] < -0.2
    assert abs(np.median(r.ao[inner]) - 0.5) < 0.01
    e = skybake.bake_ao(bowl.copy(), rule="lebedev:590")
    assert np.mean(np.abs(r.ao - e.ao)) < 0.01


def test_one_job_the_cli_and_python_give_identical_bits(cli, tmp):
    """`ao --bits` and bake_ao(store_bits=True), `prt bake` and bake_transfer run the same job: same bits."""
    m = skybake.generate_mesh("city", 3000, seed=5)
    m.compute_normals()
    src = tmp / "city.ply"
    skybake.save_mesh(src, m)
    r = skybake.bake_ao(m.copy(), rule="lebedev:110", store_bits=True)
    cli("ao", src, "-o", tmp / "out.ply", "--rule", "lebedev:110", "--bits", tmp / "out.bits", "--quiet")
    data = (tmp / "out.bits").read_bytes()
    assert data[:8] == b"SKBVIS01"
    vertices, directions, words, spec_len = np.frombuffer(data[8:24], dtype="<u4")
    assert (vertices, words) == (m.vertex_count, r.bits.shape[1])
    bits = np.frombuffer(data[24 + spec_len:], dtype="<u4").reshape(vertices, words)
    np.testing.assert_array_equal(bits, r.bits)
    out = skybake.load_mesh(tmp / "out.ply")
    np.testing.assert_array_equal(out.attribute("ao"), r.ao)

    t = skybake.bake_transfer(m.copy(), rule="lebedev:110", order=2, kind="interreflected", bounces=1)
    cli("prt", "bake", src, "-o", tmp / "prt.ply", "--rule", "lebedev:110", "--order", "2", "--bounces", "1",
        "--quiet")
    mesh, transfer, albedo = skybake.load_prt(tmp / "prt.ply")
    np.testing.assert_array_equal(transfer.coeffs, t.coeffs)


def glb_json(path):
    data = pathlib.Path(path).read_bytes()
    (length,) = struct.unpack_from("<I", data, 12)
    return json.loads(data[20:20 + length])


BOX = pathlib.Path("/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf")


@pytest.mark.skipif(not BOX.exists(), reason="assimp-testmodels is not installed")
def test_bake_file_writes_what_the_cli_writes(cli, tmp):
    """BakeFile keeps a glTF 2.0 document as `ao` and `prt bake` do: the same bytes, texture and nodes kept."""
    cli("ao", BOX, "-o", tmp / "cli.glb", "--rule", "lebedev:50", "--quiet")
    f = skybake.BakeFile(BOX, tmp / "py.glb")
    assert f.has_document
    skybake.bake_ao(f.mesh, rule="lebedev:50")
    f.save(tmp / "py.glb")
    assert (tmp / "py.glb").read_bytes() == (tmp / "cli.glb").read_bytes()
    doc = glb_json(tmp / "py.glb")
    assert doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["index"] == 0
    assert "COLOR_0" in doc["meshes"][0]["primitives"][0]["attributes"]

    cli("prt", "bake", BOX, "-o", tmp / "cli_prt.glb", "--rule", "lebedev:50", "--order", "2", "--quiet")
    f = skybake.BakeFile(BOX, tmp / "py_prt.glb")
    t = skybake.bake_transfer(f.mesh, rule="lebedev:50", order=2)
    skybake.save_prt(tmp / "py_prt.glb", f, t)
    assert (tmp / "py_prt.glb").read_bytes() == (tmp / "cli_prt.glb").read_bytes()
    assert (tmp / "py_prt.prt.json").read_text() == (tmp / "cli_prt.prt.json").read_text()
    mesh, transfer, _ = skybake.load_prt(tmp / "py_prt.glb")
    np.testing.assert_array_equal(transfer.coeffs, t.coeffs)


def test_bake_file_of_a_plain_mesh_and_its_errors(tmp):
    m = skybake.generate_mesh("bowl", 500)
    skybake.save_mesh(tmp / "bowl.ply", m)
    f = skybake.BakeFile(tmp / "bowl.ply", tmp / "bowl.glb")
    assert not f.has_document
    assert f.mesh.vertex_count == m.vertex_count
    skybake.bake_ao(f.mesh, rule="lebedev:50")
    f.save(tmp / "bowl.glb")
    assert skybake.load_mesh(tmp / "bowl.glb").attribute("ao").shape == (m.vertex_count,)
    with pytest.raises(skybake.Error, match="gltf"):
        skybake.BakeFile(tmp / "bowl.ply", tmp / "bowl.gltf")
    with pytest.raises(skybake.Error):
        skybake.BakeFile(tmp / "missing.glb", tmp / "x.glb")
