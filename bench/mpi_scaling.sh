#!/usr/bin/env bash
# Strong scaling of a distributed AO bake: 1 process against 2 MPI ranks on a
# generated mesh (1M triangles by default), same flags and backend.
#
#   bench/mpi_scaling.sh [SKYBAKE] [TRIANGLES] [RULE] [REPEATS]
#
# Baselines measured in the same run: the plain single-process bake (all
# cores), and mpirun -np 1 (the distributed path's own overhead). Two-rank
# runs are measured twice: each rank with all cores (oversubscribed when the
# ranks share a node), and each rank with cores / 2 threads (--threads).
# Prints one JSON line per configuration, then a summary line: the strong
# scaling ratio t(1) / t(2), the time rank 0 spent gathering, and the bytes
# sent per sample point. The outputs are checked to be identical. Ranks are
# not bound to cores (--bind-to none): Open MPI binds each rank to one core by
# default when there are at most 2, which would leave each rank one core.
set -euo pipefail

SKYBAKE=${1:-build/bin/skybake}
TRIANGLES=${2:-1000000}
RULE=${3:-lebedev:590}
REPEATS=${4:-3}
MPIRUN=${MPIRUN:-mpirun}
CORES=$(nproc)
HALF=$(( CORES / 2 > 0 ? CORES / 2 : 1 ))

export OMPI_MCA_btl=${OMPI_MCA_btl:-self,vader}
export OMPI_MCA_plm_rsh_agent=${OMPI_MCA_plm_rsh_agent-}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
"$SKYBAKE" -q mesh generate --kind city --triangles "$TRIANGLES" -o "$dir/mesh.glb"

# best of REPEATS: prints the JSON of the fastest run (by wall time)
measure() {
    local name=$1; shift
    local best="" best_wall=1e30
    for _ in $(seq "$REPEATS"); do
        local t0 t1 wall
        t0=$(date +%s.%N)
        "$@" > "$dir/out.json"
        t1=$(date +%s.%N)
        wall=$(python3 -c "print($t1 - $t0)")
        if python3 -c "import sys; sys.exit(0 if $wall < $best_wall else 1)"; then
            best_wall=$wall
            best=$(python3 -c "import json,sys; j=json.load(open('$dir/out.json')); j['wall_seconds']=$wall; j['config']='$name'; print(json.dumps(j))")
        fi
    done
    echo "$best" | tee "$dir/$name.json" | python3 -c "
import json, sys
j = json.load(sys.stdin)
keep = ['config', 'wall_seconds', 'seconds', 'trace_seconds', 'build_seconds', 'vertices', 'triangles', 'rays',
        'ranks', 'gathered_bytes', 'gather_seconds', 'distributed_seconds', 'points_per_rank']
print(json.dumps({k: j[k] for k in keep if k in j}))"
}

flags=(ao "$dir/mesh.glb" --rule "$RULE" --json -q)
measure single "$SKYBAKE" "${flags[@]}" -o "$dir/single.glb"
measure np1 "$MPIRUN" --oversubscribe --bind-to none -np 1 "$SKYBAKE" "${flags[@]}" -o "$dir/np1.glb"
measure np2 "$MPIRUN" --oversubscribe --bind-to none -np 2 "$SKYBAKE" "${flags[@]}" -o "$dir/np2.glb"
measure np2_split "$MPIRUN" --oversubscribe --bind-to none -np 2 "$SKYBAKE" --threads "$HALF" "${flags[@]}" -o "$dir/np2s.glb"
for f in np1 np2 np2s; do cmp -s "$dir/single.glb" "$dir/$f.glb" || { echo "mpi_scaling: $f.glb differs" >&2; exit 1; }; done

python3 - "$dir" "$CORES" "$RULE" <<'EOF'
import json, sys
d, cores, rule = sys.argv[1], int(sys.argv[2]), sys.argv[3]
r = {n: json.load(open(f"{d}/{n}.json")) for n in ("single", "np1", "np2", "np2_split")}
best2 = min(("np2", "np2_split"), key=lambda n: r[n]["wall_seconds"])
two = r[best2]
remote = sum(two["points_per_rank"][1:])
print(json.dumps({
    "summary": "mpi_scaling", "cores": cores, "rule": rule, "triangles": r["single"]["triangles"],
    "vertices": r["single"]["vertices"],
    "single_wall_s": round(r["single"]["wall_seconds"], 3), "np1_wall_s": round(r["np1"]["wall_seconds"], 3),
    "np2_wall_s": round(r["np2"]["wall_seconds"], 3), "np2_split_wall_s": round(r["np2_split"]["wall_seconds"], 3),
    "strong_scaling_ratio": round(r["single"]["wall_seconds"] / two["wall_seconds"], 3),
    "bake_seconds_single": round(r["single"]["seconds"], 3), "bake_seconds_np2": round(two["seconds"], 3),
    "bake_scaling_ratio": round(r["single"]["seconds"] / two["seconds"], 3),
    "np1_overhead_ratio": round(r["np1"]["wall_seconds"] / r["single"]["wall_seconds"], 3),
    "gather_seconds": round(two["gather_seconds"], 4),
    "gathered_bytes": two["gathered_bytes"],
    "bytes_per_point": round(two["gathered_bytes"] / remote, 2) if remote else None,
    "points_per_rank": two["points_per_rank"], "identical": True}))
EOF
