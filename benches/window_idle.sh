#!/usr/bin/env bash
# Idle CPU and closing time of the real window (release build) under Xvfb, on the built-in
# simulator, settings in a fresh temporary HOME each run.
#
#   benches/window_idle.sh [SECONDS]   servo on, homed, mouse still: CPU of the whole
#                                      process and of each thread over SECONDS (default
#                                      60), then wake-ups a second of each thread
#   benches/window_idle.sh --moving    the same while 50 mm steps go back and forth
#   benches/window_idle.sh --close [N] N times (default 5): Ctrl+Q to process exit
#
# Needs xvfb-run (xvfb, xauth) and xdotool; Linux (/proc). The clicks assume the default
# layout at 1280x800 (Servo ON, Home, the 50 step, X+ and X- of the pad).
set -euo pipefail
cd "$(dirname "$0")/.."
BIN=${XSEL_PENDANT_BIN:-target/release/xsel-pendant}

if [ -z "${WINDOW_IDLE_IN_XVFB:-}" ]; then
    [ -x "$BIN" ] || cargo build --release --bin xsel-pendant
    export WINDOW_IDLE_IN_XVFB=1
    exec xvfb-run -a -s "-screen 0 1280x800x24 -nolisten tcp" "$0" "$@"
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"; [ -n "${APP:-}" ] && kill "$APP" 2>/dev/null || true' EXIT
TICK=$(getconf CLK_TCK)

start_app() {
    rm -rf "$tmp/home"
    mkdir -p "$tmp/home"
    HOME="$tmp/home" XDG_DATA_HOME="$tmp/home/.local/share" "$BIN" >"$tmp/app.log" 2>&1 &
    APP=$!
    sleep 5
    xdotool windowfocus "$(xdotool search --pid "$APP" | head -1)" 2>/dev/null || true
}

ready() {
    xdotool mousemove 61 121 click 1 # Servo ON
    sleep 1
    xdotool mousemove 225 121 click 1 # Home
    sleep 5
    xdotool mousemove 640 790 # out of the way
    sleep 2
}

# utime + stime of the process, or of every thread as "tid name ticks" lines.
ticks() { awk '{print $14 + $15}' "/proc/$APP/stat"; }
thread_ticks() {
    for t in /proc/"$APP"/task/*; do
        echo "$(basename "$t") $(tr ' ' '_' <"$t/comm") $(awk '{print $14 + $15}' "$t/stat")"
    done | sort
}
switches() {
    for t in /proc/"$APP"/task/*; do
        echo "$(basename "$t") $(awk '/^voluntary_ctxt_switches/ {print $2}' "$t/status")"
    done | sort
}

measure() {
    local secs=$1 what=$2 moving=${3:-}
    local p0 p1 t0 t1
    p0=$(ticks)
    thread_ticks >"$tmp/t0"
    switches >"$tmp/s0"
    t0=$EPOCHREALTIME
    if [ -n "$moving" ]; then
        local end=$((SECONDS + secs))
        while [ $SECONDS -lt $end ]; do
            xdotool mousemove 186 469 click 1 # X+
            sleep 1.5
            xdotool mousemove 56 469 click 1 # X-
            sleep 1.5
        done
    else
        sleep "$secs"
    fi
    p1=$(ticks)
    thread_ticks >"$tmp/t1"
    switches >"$tmp/s1"
    t1=$EPOCHREALTIME
    local wall
    wall=$(echo "$t1 - $t0" | bc -l)
    printf '%s: %.2f %% of one core over %.1f s, VmRSS %s kB\n' "$what" \
        "$(echo "100 * ($p1 - $p0) / $TICK / $wall" | bc -l)" "$wall" \
        "$(awk '/^VmRSS/ {print $2}' "/proc/$APP/status")"
    join "$tmp/t0" "$tmp/t1" | join - <(join "$tmp/s0" "$tmp/s1") |
        awk -v tk="$TICK" -v w="$wall" \
            '{printf "  %-16s %6.2f %%  %7.1f wake-ups/s\n", $2, 100 * ($5 - $3) / tk / w, ($7 - $6) / w}' |
        sort -k2 -n -r
}

case "${1:-}" in
--close)
    for i in $(seq 1 "${2:-5}"); do
        start_app
        ready
        xdotool mousemove 186 469 click 1 # a step, still moving when the window goes
        sleep 0.3
        t0=$EPOCHREALTIME
        xdotool key ctrl+q
        while kill -0 "$APP" 2>/dev/null; do sleep 0.005; done
        printf 'close %d: Ctrl+Q to exit %.3f s\n' "$i" "$(echo "$EPOCHREALTIME - $t0" | bc -l)"
        APP=
    done
    ;;
--moving)
    start_app
    ready
    xdotool mousemove 237 202 click 1 # the 50 mm step
    measure "${2:-30}" "moving (50 mm steps every 1.5 s)" moving
    ;;
*)
    start_app
    ready
    measure "${1:-60}" "idle (connected, servo on, homed, mouse still)"
    ;;
esac
