#!/usr/bin/env bash
# Start-up time and resident memory of the real window (release build) under Xvfb, on the
# built-in simulator, with settings kept in a fresh temporary XDG_DATA_HOME each run.
#
#   benches/window_startup.sh [N]            N starts (default 10): time from spawn to the
#                                            end of the first ui() call, and to the exit
#                                            that the app asks for right after that frame
#   benches/window_startup.sh --rss [MIN]    one idle, polling window for MIN minutes
#                                            (default 10): VmRSS and CPU time each minute
#
# Needs xvfb-run (xvfb, xauth). Builds target/release/xsel-pendant when it is missing.
# XSEL_PENDANT_ARGS adds flags to the app's command line (e.g. "--renderer wgpu").
# The app's probe (XSEL_PENDANT_FIRST_FRAME, XSEL_PENDANT_EXIT_AFTER_FIRST_FRAME) is
# described in src/ui/start.rs, `BenchHooks` (the binary reads it from its environment).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${XSEL_PENDANT_BIN:-target/release/xsel-pendant}
read -r -a APP_ARGS <<<"${XSEL_PENDANT_ARGS:-}"

if [ -z "${WINDOW_STARTUP_IN_XVFB:-}" ]; then
    [ -x "$BIN" ] || cargo build --release --bin xsel-pendant
    export WINDOW_STARTUP_IN_XVFB=1
    exec xvfb-run -a -s "-screen 0 1280x800x24 -nolisten tcp" "$0" "$@"
fi

# Microseconds since the Unix epoch, without forking (bash 5).
now_us() { local t=${EPOCHREALTIME//[.,]/}; echo "$t"; }

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# Prints median, p99 and max (ms) of the microsecond samples in file $2, labelled $1.
stats() {
    sort -n "$2" | awk -v what="$1" '
        { v[NR] = $1 }
        END {
            n = NR; if (n == 0) { print what ": no samples"; exit }
            med = v[int(n / 2) + 1]; k = int((n * 99 + 99) / 100); p99 = v[k]
            printf "%-40s median %8.1f ms   p99 %8.1f ms   max %8.1f ms   (n=%d)\n",
                what, med / 1000, p99 / 1000, v[n] / 1000, n
        }'
}

startup() {
    local n=${1:-10} i data t0 t1 ff
    : >"$tmp/first" ; : >"$tmp/exit"; : >"$tmp/app"
    for i in $(seq 1 "$n"); do
        data=$(mktemp -d "$tmp/data.XXXX")
        t0=$(now_us)
        XDG_DATA_HOME=$data XSEL_PENDANT_FIRST_FRAME=1 XSEL_PENDANT_EXIT_AFTER_FIRST_FRAME=1 \
            timeout 60 "$BIN" "${APP_ARGS[@]}" >/dev/null 2>"$data/stderr" || {
            echo "run $i failed:" >&2; cat "$data/stderr" >&2; exit 1; }
        t1=$(now_us)
        ff=$(sed -n 's/^first frame unix_us=\([0-9]*\) app_us=\([0-9]*\).*/\1 \2/p' "$data/stderr" | head -n1)
        [ -n "$ff" ] || { echo "run $i: no 'first frame' line:" >&2; cat "$data/stderr" >&2; exit 1; }
        echo $(( ${ff% *} - t0 )) >>"$tmp/first"
        echo "${ff#* }" >>"$tmp/app"
        echo $(( t1 - t0 )) >>"$tmp/exit"
        printf 'run %2d: first frame %7.1f ms, exit %7.1f ms\n' "$i" \
            "$(( ${ff% *} - t0 ))e-3" "$(( t1 - t0 ))e-3"
    done
    echo "start-up of $BIN under Xvfb 1280x800x24, $n runs, $(nproc) cores, load $(cut -d' ' -f1-3 /proc/loadavg)"
    stats "spawn to end of first ui()" "$tmp/first"
    stats "app created to end of first ui()" "$tmp/app"
    stats "spawn to exit after first frame" "$tmp/exit"
}

rss() {
    local minutes=${1:-10} data pid m deadline ticks
    data=$(mktemp -d "$tmp/data.XXXX")
    XDG_DATA_HOME=$data XSEL_PENDANT_FIRST_FRAME=1 "$BIN" "${APP_ARGS[@]}" >/dev/null 2>"$data/stderr" &
    pid=$!
    deadline=$(( $(now_us) + 60000000 ))
    until grep -q '^first frame' "$data/stderr"; do
        kill -0 "$pid" 2>/dev/null || { echo "the app exited:" >&2; cat "$data/stderr" >&2; exit 1; }
        [ "$(now_us)" -lt "$deadline" ] || { echo "no first frame within 60 s" >&2; kill "$pid"; exit 1; }
        sleep 0.05
    done
    ticks=$(getconf CLK_TCK)
    echo "idle window under Xvfb, $minutes minutes, $(nproc) cores (pid $pid) ${APP_ARGS[*]}"
    echo "minute  VmRSS(kB)  VmHWM(kB)  CPU(s)"
    for m in $(seq 0 "$minutes"); do
        [ "$m" -eq 0 ] || sleep 60
        kill -0 "$pid" 2>/dev/null || { echo "the app exited early:" >&2; cat "$data/stderr" >&2; exit 1; }
        awk -v m="$m" -v stat="$(cut -d' ' -f14,15 /proc/$pid/stat)" -v hz="$ticks" '
            /^VmRSS:/ { rss = $2 } /^VmHWM:/ { hwm = $2 }
            END { split(stat, t, " "); printf "%6d  %9d  %9d  %6.1f\n", m, rss, hwm, (t[1] + t[2]) / hz }
        ' "/proc/$pid/status"
    done
    kill "$pid"
    deadline=$(( $(now_us) + 10000000 ))
    while kill -0 "$pid" 2>/dev/null && [ "$(now_us)" -lt "$deadline" ]; do sleep 0.05; done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
    wait "$pid" 2>/dev/null || true
}

case "${1:-}" in
    --rss) rss "${2:-10}" ;;
    *) startup "${1:-10}" ;;
esac
