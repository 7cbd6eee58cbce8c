#!/usr/bin/env python3
"""End-to-end tests of distributed bakes: `mpirun -np K skybake ao|prt bake ...`.

    mpi_cli_test.py --skybake BIN --has-mpi ON|OFF [--mpirun PATH] CASE

Each CASE is one ctest test. Exit 0: passed; 1: failed; 77: skipped (no MPI
in the build, or no mpirun). The reference of every distributed bake is the
single-process bake of the same mesh, flags and backend: their files must be
equal byte for byte.
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

SKIP = 77
NO_MPI = "this skybake was built without MPI: configure with -DSKYBAKE_WITH_MPI=ON and install libopenmpi-dev"
MODELS = "/usr/share/assimp/models"

args = None
work = None


class Failure(Exception):
    pass


def check(cond, what, result=None):
    if not cond:
        extra = ""
        if result is not None:
            extra = f"\n  exit {result.returncode}\n  stderr:\n{result.stderr}"
        raise Failure(what + extra)


def mpi_env():
    env = dict(os.environ)
    # A container as root, without a network: shared memory only, no ssh.
    env.update({
        "OMPI_MCA_btl": "self,vader",
        "OMPI_MCA_plm_rsh_agent": "",
        "OMPI_MCA_btl_vader_single_copy_mechanism": "none",
        "OMPI_ALLOW_RUN_AS_ROOT": "1",
        "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    })
    return env


def run(cmd, env=None, timeout=300):
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)


def skybake(*a):
    r = run([args.skybake, "-q", *a])
    check(r.returncode == 0, f"skybake {' '.join(a)} failed", r)
    return r


def mpirun(np, *a, env_extra=None):
    env = mpi_env()
    cmd = [args.mpirun, "--allow-run-as-root", "--oversubscribe", "-np", str(np)]
    for k, v in (env_extra or {}).items():
        env[k] = v
        cmd += ["-x", k]
    return run(cmd + [args.skybake, "-q", *a], env=env)


def skybake_lines(stderr):
    return [l for l in stderr.splitlines() if "skybake:" in l]


def same_files(a, b):
    with open(a, "rb") as fa, open(b, "rb") as fb:
        return fa.read() == fb.read()


def generate(kind, triangles, name):
    path = os.path.join(work, name)
    skybake("mesh", "generate", "--kind", kind, "--triangles", str(triangles), "-o", path)
    return path


def truck():
    dst = os.path.join(work, "truck")
    if not os.path.exists(dst):
        shutil.copytree(os.path.join(MODELS, "glTF", "CesiumMilkTruck"), dst)
    return os.path.join(dst, "CesiumMilkTruck.gltf")


def fresh_dir(name):
    d = os.path.join(work, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def expect_identical(mesh, files, flags, ranks, command=("ao",)):
    """Bakes `mesh` in one process and under mpirun with each rank count;
    every file of `files` (names in the output folder) must be equal."""
    ref = fresh_dir("ref")
    skybake(*command, mesh, "-o", os.path.join(ref, files[0]), *flags)
    for np in ranks:
        out = fresh_dir(f"np{np}")
        r = mpirun(np, *command, mesh, "-o", os.path.join(out, files[0]), *flags)
        check(r.returncode == 0, f"mpirun -np {np} {' '.join(command)} {' '.join(flags)} failed", r)
        for f in files:
            check(same_files(os.path.join(ref, f), os.path.join(out, f)),
                  f"{f} of -np {np} differs from the single-process bake ({' '.join(flags)})")


def expect_job_failed(r, out_dir, needle):
    check(r.returncode != 0, "the job exited 0", r)
    lines = skybake_lines(r.stderr)
    check(len(lines) == 1, f"{len(lines)} skybake lines on stderr, not one", r)
    check(needle in lines[0], f"'{needle}' not in the error line", r)
    left = os.listdir(out_dir)
    check(not left, f"files were written: {left}", r)


# --- cases ---------------------------------------------------------------------------

def case_identical_vertex():
    city = generate("city", 20000, "city.glb")
    for rule in ("lebedev:50", "fibonacci:64+rotate"):
        expect_identical(city, ["out.glb"], ["--rule", rule, "--backend", "embree"], [1, 2, 3, 4])
    small = generate("city", 3000, "small.glb")
    expect_identical(small, ["out.glb"], ["--rule", "lebedev:50", "--backend", "brute"], [1, 2, 3, 4])
    # Per-vertex results other than AO: the PRT transfer and its bounces (rank 0).
    expect_identical(small, ["out.glb", "out.prt.json"], ["--rule", "lebedev:50", "--order", "2"], [2, 3],
                     command=("prt", "bake"))
    expect_identical(small, ["out.glb", "out.prt.json"], ["--rule", "lebedev:50", "--bounces", "1"], [3],
                     command=("prt", "bake"))


def case_identical_texture():
    mesh = truck()
    for backend in ("embree", "brute"):
        expect_identical(mesh, ["out.glb", "out_ao.png"],
                         ["--texture", "64", "--rule", "lebedev:50", "--backend", backend], [1, 2, 3, 4])


def case_fault_chunk():
    city = generate("city", 20000, "city.glb")
    for rank in (0, 1):
        out = fresh_dir(f"fault{rank}")
        r = mpirun(3, "ao", city, "-o", os.path.join(out, "out.glb"), "--rule", "lebedev:50",
                   env_extra={"SKYBAKE_TEST_MPI_FAIL_RANK": str(rank), "SKYBAKE_TEST_MPI_FAIL_AT": "chunk"})
        expect_job_failed(r, out, f"test failure at 'chunk' on rank {rank}")


def case_fault_kill():
    city = generate("city", 20000, "city.glb")
    out = fresh_dir("killed")
    r = mpirun(3, "ao", city, "-o", os.path.join(out, "out.glb"), "--rule", "lebedev:50",
               env_extra={"SKYBAKE_TEST_MPI_FAIL_RANK": "1", "SKYBAKE_TEST_MPI_FAIL_AT": "kill"})
    check(r.returncode != 0, "the job exited 0 with a rank killed", r)
    check(len(skybake_lines(r.stderr)) <= 1, "more than one skybake line", r)
    check(not os.listdir(out), f"files were written: {os.listdir(out)}", r)


def case_fault_load():
    city = generate("city", 2000, "city.glb")
    out = fresh_dir("load")
    r = mpirun(3, "ao", city, "-o", os.path.join(out, "out.glb"), "--rule", "lebedev:50",
               env_extra={"SKYBAKE_TEST_MPI_FAIL_RANK": "2", "SKYBAKE_TEST_MPI_FAIL_AT": "load"})
    expect_job_failed(r, out, "test failure at 'load' on rank 2")
    # A missing input: every rank fails alike, one line.
    r = mpirun(3, "ao", os.path.join(work, "missing.glb"), "-o", os.path.join(out, "out.glb"))
    expect_job_failed(r, out, "missing.glb")
    # A bad flag: exit 2 (usage), one line.
    r = mpirun(2, "prt", "bake", city, "-o", os.path.join(out, "out.glb"), "--rule", "bogus")
    expect_job_failed(r, out, "--rule")
    check(r.returncode == 2, "a usage error exits 2", r)


def batch_assets():
    src = fresh_dir("assets")
    for kind in ("sphere", "torus", "wall", "bowl"):
        skybake("mesh", "generate", "--kind", kind, "--triangles", "2000", "-o", os.path.join(src, kind + ".glb"))
    with open(os.path.join(src, "broken.obj"), "w") as f:
        f.write("not a mesh\n")
    listing = os.path.join(work, "assets.txt")
    with open(listing, "w") as f:
        f.write("# good and bad\nassets/sphere.glb\nassets/broken.obj\n\nassets/torus.glb\n"
                "assets/wall.glb\n  assets/bowl.glb  \n")
    return src, listing


def case_batch():
    good = ["sphere", "torus", "wall", "bowl"]
    flags = ["--rule", "lebedev:50"]
    for np, launcher in ((3, "mpirun"), (1, "none")):
        src, listing = batch_assets()
        out = fresh_dir(f"batch-{launcher}")
        cmd = ["ao", "--batch", listing, "--out-dir", out, *flags]
        r = mpirun(np, *cmd) if launcher == "mpirun" else run([args.skybake, "-q", *cmd])
        check(r.returncode == 1, "a batch with a failure exits 1", r)
        check("5 assets: 4 baked, 0 current (skipped), 1 failed" in r.stderr, "summary", r)
        check("failed: " in r.stderr and "broken.obj" in r.stderr, "the broken asset is listed", r)
        check(sorted(os.listdir(out)) == sorted([g + ".glb" for g in good] + [g + ".glb.bake.json" for g in good]),
              f"outputs: {sorted(os.listdir(out))}", r)
        # Each equals the single-process bake of that asset.
        ref = fresh_dir("batch-ref")
        for g in good:
            skybake("ao", os.path.join(src, g + ".glb"), "-o", os.path.join(ref, g + ".glb"), *flags)
            check(same_files(os.path.join(ref, g + ".glb"), os.path.join(out, g + ".glb")), f"{g}.glb differs")
        stamps = {g: os.stat(os.path.join(out, g + ".glb")).st_mtime_ns for g in good}
        # A rerun skips the current outputs (and still reports the broken one).
        r = mpirun(np, *cmd) if launcher == "mpirun" else run([args.skybake, "-q", *cmd])
        check(r.returncode == 1 and "0 baked, 4 current (skipped), 1 failed" in r.stderr, "rerun skips", r)
        check(all(os.stat(os.path.join(out, g + ".glb")).st_mtime_ns == stamps[g] for g in good), "rewritten")
        # Other flags: not current any more.
        r = run([args.skybake, "-q", "ao", "--batch", listing, "--out-dir", out, "--rule", "lebedev:110"])
        check("4 baked, 0 current" in r.stderr, "a flag change bakes again", r)
        # A newer input: that asset alone is baked again.
        t = os.stat(os.path.join(out, "wall.glb")).st_mtime_ns + 10**9
        os.utime(os.path.join(src, "wall.glb"), ns=(t, t))
        r = run([args.skybake, "-q", "ao", "--batch", listing, "--out-dir", out, "--rule", "lebedev:110"])
        check("1 baked, 3 current" in r.stderr, "a touched input bakes again", r)


def case_mpi_flag():
    city = generate("city", 2000, "city.glb")
    out = fresh_dir("flag")
    r = run([args.skybake, "-q", "ao", city, "-o", os.path.join(out, "out.glb"), "--mpi"])
    if args.has_mpi != "ON":
        # The stub: one clear line, exit 1, nothing written.
        check(r.returncode == 1, "--mpi without MPI exits 1", r)
        lines = skybake_lines(r.stderr)
        check(len(lines) == 1 and NO_MPI in lines[0], "the no-MPI error line", r)
        check(not os.listdir(out), "nothing written", r)
        return
    # A job of one process without a launcher: the same bytes as without --mpi.
    check(r.returncode == 0, "--mpi as a job of one", r)
    skybake("ao", city, "-o", os.path.join(out, "ref.glb"))
    check(same_files(os.path.join(out, "out.glb"), os.path.join(out, "ref.glb")), "--mpi output differs")


CASES = {name[5:]: fn for name, fn in globals().items() if name.startswith("case_")}


def main():
    global args, work
    p = argparse.ArgumentParser()
    p.add_argument("--skybake", required=True)
    p.add_argument("--mpirun", default=shutil.which("mpirun") or "")
    p.add_argument("--has-mpi", default="OFF")
    p.add_argument("case", choices=sorted(CASES))
    args = p.parse_args()
    if args.case != "mpi_flag":
        if args.has_mpi != "ON":
            print("skipped: this skybake was built without MPI")
            return SKIP
        if not args.mpirun or not os.path.exists(args.mpirun):
            print("skipped: no mpirun")
            return SKIP
    work = tempfile.mkdtemp(prefix=f"skybake-mpi-{args.case}-")
    try:
        CASES[args.case]()
    except Failure as e:
        print(f"FAILED: {e}")
        return 1
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
