#!/usr/bin/env bash
# GPU readiness in one command, for the rare session lent a GPU (and here, on lavapipe, so that
# it is known to work before): on one device,
#   1. the Vulkan devices the build sees (ray queries or not);
#   2. the test suite's Vulkan tests on that device;
#   3. the reference office (examples/reference-office's model; small: 1425 sensors, large:
#      14250) V and DC (each also with -asub 3) and C_ds on the GPU by both traversals, beside
#      Embree on the same machine: wall seconds, and each GPU matrix's difference from
#      Embree's at the same seed (the two run one estimator with one random stream, so this is
#      float rounding, not noise); and DAYSIM's diffuse run (rtrace_dc-gpu -Dd, DAYSIM's
#      settings) without (DSdif) and with (DSdifC, -aa 0.1) the sensor cache; and T, genBSDF of
#      the office's blinds (glass, slats, head box and guides) at -c 500; and the three- and
#      five-phase matrices D, Vd (V_d) and Dd (D_d) of examples/reference-office/Makefile.phases
#      (not in the default CASES: add them by name).
# Writes OUT/gpu.csv (model,case,program,sensors,wall_s,rel_rms_vs_embree), OUT/summary.txt and
# the logs. On an H100 machine (16 cores for Embree), 2026-11-25: MODELS=small with the tests
# 441 s, MODELS=large TESTS=0 402 s (96 s of it C_ds on the GPU): two calls within the device
# tool's 10 minutes. On an H200, 2026-11-26: MODELS=small TEST_SHARDS=6 178 s (the tests 116 s
# of it), MODELS=large TESTS=0 CASES="V DC DSdif DSdifC" about 200 s, C_ds large 60 s more.
# On an H100, 2026-11-27, fresh machine: MODELS=small TEST_SHARDS=8 (every case) 494 s (the
# tests 244 s, then each case's pipeline compiled cold), MODELS=large TESTS=0 CASES="Cds DCsub"
# 222 s.
#
# usage: bench/gpu.sh    (from the repository root)
# environment: BUILD (build: a build tree, or bench/gpu_bundle.sh's copy), DEVICE (0; llvmpipe
#   here), OUT (bench/results/gpu), MODELS ("small large"), QUICK (1: every 30th sensor and low
#   settings, for lavapipe), TESTS (0 skips step 2), TEST_SHARDS (1: test processes side by side,
#   each compiling its own pipelines: NVIDIA's compiler is most of step 2), CASES ("V Vsub DC
#   DCsub Cds DSdif DSdifC T"; "" runs none; also D Vd Dd;
#   DCsub: DC with -asub 3, whose probes a GPU slice of
#   one row asks for three; Vsub: V with -asub 3, whose surfaces sample the window directly),
#   FP64 (1: also vulkan-bvh-fp64, the BVH walk with bins and accumulators in double,
#   -gpu_cal double -gpu_accum double, as the engine was before it went without fp64),
#   SPIRV_NONE (1: also vulkan-bvh-O0, the BVH walk with unoptimised SPIR-V, -gpu_spirv_opt
#   none, which lavapipe runs 1.1-1.3x sooner: does NVIDIA's compiler too?),
#   PATHS (1: also vulkan-bvh-paths, the BVH walk on the paths engine, -gpu_engine paths: an
#   invocation a first-hemisphere cell's path, records in fixed point; and its replay beside the
#   tasks engine's),
#   REPLAY (the rcontrib cases also measured by bench/gpu_replay_bench.cpp on each traversal:
#   rays traced, rays a second, the device's seconds per stage from timestamps, and the GPU
#   efficiency, run rays/s over the rate of a kernel replaying its rays for their nearest hits
#   alone; default "V DC Cds"; OUT/replay.csv), REPLAY_EVERY (the replay logs every K-th
#   sensor's rays: 10), REPLAY_SCRATCH_MIB (MiB, a list: the paths engine's replay again with
#   that much device memory a dispatch, its walkers half of it, in place of the device's budget
#   of a quarter of its memory, at most 2 GiB: do more walkers at once pay?), REPLAY_WAVES
#   (a list: the paths engine's replay again with -gpu_waves N, its walkers taking N steps as
#   waves, a dispatch to their next rays and one to those rays' hits, before one walks them
#   to the end: stage3_s and stage4_s in replay.csv), COMPILE (spirv-opt levels whose pipeline creation for the first model's
#   DC shader is timed, one sensor at -ad 16 on the BVH traversal: cold, with every cache empty
#   and the drivers' disabled; driver, with our SPIR-V cached; warm, with the driver's cache
#   too; default "performance size none"; OUT/compile.csv; up to 35 s a cold one on NVIDIA)
# On the device machine (device/README.md): bench/gpu_bundle.sh here, then, there, with .gpu and
# .gl carried: for f in .gl/*.deb; do dpkg -x $f /; done; ldconfig; BUILD=.gpu bench/gpu.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BUILD=$(realpath "${BUILD:-$root/build}")
DEVICE=${DEVICE:-0}
OUT=$(realpath -m "${OUT:-$root/bench/results/gpu}")
MODELS=${MODELS:-"small large"}
QUICK=${QUICK:-0}
TESTS=${TESTS:-1}
TEST_SHARDS=${TEST_SHARDS:-1}
CASES=${CASES-"V Vsub DC DCsub Cds DSdif DSdifC T"}
FP64=${FP64:-0}
REPLAY=${REPLAY-"V DC Cds"}
REPLAY_EVERY=${REPLAY_EVERY:-10}
REPLAY_SCRATCH_MIB=${REPLAY_SCRATCH_MIB-}
REPLAY_WAVES=${REPLAY_WAVES-}
REPLAY_BENCH=$BUILD/bench/gpu_replay_bench
COMPILE=${COMPILE-"performance size none"}
RCONTRIB=$BUILD/bin/rcontrib-gpu
if [ -f "$BUILD/gpu.tar.xz" ] && [ ! -x "$RCONTRIB" ]; then  # bench/gpu_bundle.sh's archive
    tar -C "$BUILD" -xJf "$BUILD/gpu.tar.xz"
fi
[ -d "$BUILD/runtime" ] && export LD_LIBRARY_PATH="$BUILD/runtime${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
mkdir -p "$OUT"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
start=$(date +%s)
summary=$OUT/summary.txt
csv=$OUT/gpu.csv
echo "model,case,program,sensors,wall_s,rel_rms_vs_embree" > "$csv"
replay_csv=$OUT/replay.csv
: > "$replay_csv"
{
    echo "bench/gpu.sh $(date -u +%Y-%m-%dT%H:%MZ) on $(hostname), $(nproc) cores, device $DEVICE"
    echo "commit $(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
} > "$summary"

# 1. devices
echo "== Vulkan devices" | tee -a "$summary"
"$RCONTRIB" -devices | tee -a "$summary"

# 2. the test suite's Vulkan tests on the device
if [ "$TESTS" != 0 ]; then
    echo "== Vulkan tests on device $DEVICE" | tee -a "$summary"
    t0=$(date +%s)
    set +e
    pids=()
    for ((shard = 0; shard < TEST_SHARDS; shard++)); do
        DAYFLUX_VULKAN_DEVICE=$DEVICE GALLIVM_PERF=${GALLIVM_PERF-nopt} \
            DAYFLUX_TEST_DATA_DIR=$root/test/data DAYFLUX_TEST_BIN_DIR=$BUILD/bin \
            GTEST_TOTAL_SHARDS=$TEST_SHARDS GTEST_SHARD_INDEX=$shard \
            "$BUILD/test/dayflux_tests" --gtest_filter='*Vulkan*' > "$OUT/tests$shard.log" 2>&1 &
        pids+=($!)
    done
    status=0
    for pid in "${pids[@]}"; do wait "$pid" || status=$?; done
    set -e
    cat "$OUT"/tests[0-9]*.log > "$OUT/tests.log"
    rm -f "$OUT"/tests[0-9]*.log
    grep -E "^\[  (PASSED|FAILED|SKIPPED) " "$OUT/tests.log" | tee -a "$summary" || true
    echo "exit status $status, $(($(date +%s) - t0)) s" | tee -a "$summary"
fi

# 3. the reference office
if [ "$QUICK" = 1 ]; then
    stride=30 v_ad=1024 dc_ad=512
else
    stride=1 v_ad=10000 dc_ad=4096
fi
V_ARGS="-I+ -ab 8 -ad $v_ad -lw 2e-5 -faf -f klems_full.cal -b kbin(0,1,0,0,0,1) -bn Nkbins -m glass_mat"
DC_ARGS="-I+ -ab 6 -ad $dc_ad -lw 5e-5 -faf -e MF:1 -f reinhart.cal -b rbin -bn Nrbins -m skyglow"
CDS_ARGS="-I+ -ab 0 -dc 1 -dt 0 -dj 0 -faf -e MF:6 -f reinhart.cal -b rbin -bn Nrbins -m solar"
DS_ARGS="-I+ -oc -faf -ab 5 -ad 1000 -ar 300 -dj 0 -st 0.15 -L 1000 -N 148 -Dd"
export RAYPATH=.:$root/lib
programs=("embree|-backend embree" "vulkan-rayquery|-device $DEVICE -gpu_traversal rayquery"
          "vulkan-bvh|-device $DEVICE -gpu_traversal bvh")
[ "$FP64" = 1 ] &&
    programs+=("vulkan-bvh-fp64|-device $DEVICE -gpu_traversal bvh -gpu_cal double -gpu_accum double")
[ "${SPIRV_NONE:-0}" = 1 ] &&
    programs+=("vulkan-bvh-O0|-device $DEVICE -gpu_traversal bvh -gpu_spirv_opt none")
engines=tasks
if [ "${PATHS:-0}" = 1 ]; then
    programs+=("vulkan-bvh-paths|-device $DEVICE -gpu_traversal bvh -gpu_engine paths")
    engines="tasks paths"
fi
echo "== reference office (wall s; relative RMS difference from Embree at the same seed)" |
    tee -a "$summary"
printf "%-6s %-4s %-16s %8s %10s %12s\n" model case program sensors wall_s vs_embree |
    tee -a "$summary"
for model in $MODELS; do
    offices=1
    [ "$model" = large ] && offices=10
    dir=$tmp/$model
    mkdir -p "$dir"
    python3 "$root/examples/reference-office/make_office.py" --offices "$offices" --blinds \
        --out "$dir/model" > /dev/null 2>> "$OUT/office.log"
    awk -v s="$stride" '(NR - 1) % s == 0' "$dir/model/sensors.pts" > "$dir/sensors.pts"
    sensors=$(wc -l < "$dir/sensors.pts")
    # V: the window's glass a glow receiver; DC: the example's sky (and ground) glow.
    sed 's/^void glass glass_mat .*$/void glow glass_mat 0 0 4 1 1 1 0/' \
        "$dir/model/materials.rad" > "$dir/vmaterials.rad"
    printf 'void glow sky 0 0 4 1000 1000 1000 0\nsky source himmel 0 0 4 0 0 1 360\n' \
        > "$dir/sky148.rad"
    for case in $CASES; do
        program=$RCONTRIB
        case $case in
            V) args="$V_ARGS vmaterials.rad model/office.rad model/glass.rad" ;;
            Vsub) args="-asub 3 $V_ARGS vmaterials.rad model/office.rad model/glass.rad" ;;
            DC) args="$DC_ARGS model/materials.rad model/office.rad model/glass.rad model/sky.rad" ;;
            DCsub)
                args="-asub 3 $DC_ARGS model/materials.rad model/office.rad model/glass.rad"
                args="$args model/sky.rad" ;;
            Cds) args="$CDS_ARGS model/materials.rad model/office.rad model/glass.rad model/suns.rad" ;;
            DSdif | DSdifC)
                program=$BUILD/bin/rtrace_dc-gpu
                # (the same -lw per sample both ways: rtrace_dc-gpu divides it by -ad with -aa)
                args="$DS_ARGS $([ $case = DSdifC ] && echo -aa 0.1 -lw 0.004 -lr 6 ||
                                  echo -aa 0 -lw 4e-6 -lr -6)"
                args="$args sky148.rad model/materials.rad model/office.rad model/glass.rad" ;;
            # The phase matrices as examples/reference-office/Makefile.phases makes them (with
            # the blinds' head box and guides in D), rfluxmtx-gpu passing the engine options on.
            D)
                program=$BUILD/bin/rfluxmtx-gpu
                args="-ab 2 -ad 1024 -lw 1e-3 -c $([ "$QUICK" = 1 ] && echo 50 || echo 1000) -faf"
                args="$args model/window.rad model/skydome.rad model/materials.rad"
                args="$args model/office.rad model/blinds_frame.rad" ;;
            Vd)
                program=$BUILD/bin/rfluxmtx-gpu
                args="-I+ -ab 1 -ad $dc_ad -lw 5e-5 -faf - model/window.rad"
                args="$args model/materials_black.rad model/office.rad" ;;
            Dd)
                program=$BUILD/bin/rfluxmtx-gpu
                args="-ab 0 -c $([ "$QUICK" = 1 ] && echo 50 || echo 1000) -faf model/window.rad"
                args="$args model/skydome.rad model/materials_black.rad model/office.rad" ;;
            T)
                program=$BUILD/bin/genBSDF
                args="-c $([ "$QUICK" = 1 ] && echo 20 || echo 500) $(cat "$dir/model/blinds_system.dim")"
                args="$args model/blinds_system.rad" ;;
        esac
        for p in "${programs[@]}"; do
            name=${p%%|*}
            out=$dir/$case-$name.fmx
            if [[ $name == vulkan* ]]; then  # compile the shader first: not what is measured
                warm=$args
                case $case in T | D | Dd) warm=$(sed 's/-c [0-9]*/-c 1/' <<< "$args") ;; esac
                (cd "$dir" && head -2 sensors.pts | "$program" ${p#*|} -seed 1 $warm \
                    > /dev/null 2> "$dir/err")
                if grep -q "using Embree" "$dir/err"; then
                    printf "%-6s %-4s %-16s %8s %10s %12s\n" "$model" "$case" "$name" "$sensors" \
                        "n/a" "$(grep -o 'cannot take this run ([^;]*' "$dir/err" | head -1)" |
                        tee -a "$summary"
                    echo "$model,$case,$name,$sensors,," >> "$csv"
                    continue
                fi
            fi
            # bash's own clock: the device machine's image has no /usr/bin/time
            t0=$(date +%s.%N)
            (cd "$dir" && "$program" ${p#*|} -seed 1 $args < sensors.pts > "$out" \
                2> "$dir/err") || { cat "$dir/err"; exit 1; }
            awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f\n", b - a }' > "$dir/time"
            diff=$([ "$name" = embree ] && echo 0 ||
                   python3 "$root/bench/rcontrib_error.py" "$out" "$dir/$case-embree.fmx")
            printf "%-6s %-4s %-16s %8s %10s %12s\n" "$model" "$case" "$name" "$sensors" \
                "$(cat "$dir/time")" "$diff" | tee -a "$summary"
            echo "$model,$case,$name,$sensors,$(cat "$dir/time"),$diff" >> "$csv"
        done
        # The GPU efficiency: the run's rays a second over its replay's (gpu_replay_bench.cpp).
        if [[ " $REPLAY " == *" $case "* && $program == "$RCONTRIB" && -x $REPLAY_BENCH ]]; then
            runs=$(for e in $engines; do echo "rayquery,$e,0,0 bvh,$e,0,0"; done
                   for mib in $REPLAY_SCRATCH_MIB; do echo "bvh,paths,$mib,0"; done
                   for waves in $REPLAY_WAVES; do echo "bvh,paths,0,$waves"; done)
            for run in $runs; do
                IFS=, read -r traversal engine mib waves <<< "$run"
                label=$traversal+$engine
                [ "$mib" = 0 ] || label="$label@${mib}MiB"
                [ "$waves" = 0 ] || label="$label+${waves}waves"
                (cd "$dir" && "$REPLAY_BENCH" -record_every "$REPLAY_EVERY" -repeat 3 \
                    -scratch_mib "$mib" -backend vulkan -device "$DEVICE" \
                    -gpu_traversal "$traversal" -gpu_engine "$engine" -gpu_waves "$waves" \
                    -seed 1 $args \
                    < sensors.pts > "$dir/replay.csv" 2> "$dir/err") || {
                    echo "$model $case $label replay: $(tail -1 "$dir/err")" | tee -a "$summary"
                    continue
                }
                [ -s "$replay_csv" ] ||
                    echo "model,case,traversal+engine,$(head -1 "$dir/replay.csv")" > "$replay_csv"
                echo "$model,$case,$label,$(tail -1 "$dir/replay.csv")" >> "$replay_csv"
                tail -1 "$replay_csv" | awk -F, '{ printf "replay %s %s %s: %s rays, run %s Mrays/s (stages %s s, %s s, %s s, %s s), replay %s Mrays/s, efficiency %s\n", $1, $2, $3, $6, $11, $9, $10, $18, $19, $16, $17 }' |
                    tee -a "$summary"
            done
        fi
    done
done
# 4. compile time (issue 42's step 4): the DC shader's pipeline, per spirv-opt level
if [ -n "$COMPILE" ]; then
    echo "== compile time, DC shader (s): cold, driver only, warm" | tee -a "$summary"
    echo "level,cold_s,driver_s,warm_s" > "$OUT/compile.csv"
    model=${MODELS%% *}
    dir=$tmp/$model
    head -1 "$dir/sensors.pts" > "$dir/one.pts"
    once=(-device "$DEVICE" -gpu_traversal bvh -I+ -ab 6 -ad 16 -lw 5e-5 -faf -e MF:1
          -f reinhart.cal -b rbin -bn Nrbins -m skyglow model/materials.rad model/office.rad
          model/glass.rad model/sky.rad)
    timed() {  # seconds of one run, with the environment given
        local t0
        t0=$(date +%s.%N)
        (cd "$dir" && env "$@" "$RCONTRIB" -gpu_spirv_opt "$level" "${once[@]}" < one.pts \
            > /dev/null 2> "$dir/err") || { cat "$dir/err"; exit 1; }
        awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }'
    }
    for level in $COMPILE; do
        cache=$(mktemp -d)
        no_driver_cache=(XDG_CACHE_HOME="$cache" MESA_SHADER_CACHE_DISABLE=true
                         __GL_SHADER_DISK_CACHE=0)
        cold=$(timed "${no_driver_cache[@]}")
        driver=$(timed "${no_driver_cache[@]}")
        timed XDG_CACHE_HOME="$cache" > /dev/null  # fills the drivers' caches
        warm=$(timed XDG_CACHE_HOME="$cache")
        rm -rf "$cache"
        echo "$level,$cold,$driver,$warm" >> "$OUT/compile.csv"
        echo "$level: cold $cold, driver $driver, warm $warm" | tee -a "$summary"
    done
fi
echo "total $(($(date +%s) - start)) s" | tee -a "$summary"
