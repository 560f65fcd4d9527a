#!/bin/bash
# Run one G-code program on the simulated servo mill (LinuxCNC 2.9, headless)
# and leave the halsampler trace at OUT_TRACE.
#
#   integration/linuxcnc/run_program.sh PROGRAM.nc OUT_TRACE.txt
#
# Environment (optional):
#   SERVOTWIN_TIMEOUT   seconds for the display script (default 120); the
#                       whole run is cut off 60 s after that (or after
#                       SERVOTWIN_OVERALL_TIMEOUT seconds)
#   SERVOTWIN_MDI       MDI commands sent before the program, '|'-separated
#   SERVOTWIN_PRE_ROLL, SERVOTWIN_SETTLE  seconds traced before / after
#   SERVOTWIN_INI       another INI to use instead of servotwin_sim.ini (e.g.
#                       other dynamics); it is copied next to the HAL file
#   SERVOTWIN_KEEP_RUNDIR=1  keep the scratch run directory
#   SERVOTWIN_LCNC_USER unprivileged user for rtapi_app when run as root
#                       (default linuxcnc-sim, created if missing)
#
# Exit status: 0 when the program ran to its end and the trace is complete;
# non-zero otherwise (messages say why). LinuxCNC is shut down in all cases.
#
# Why things are done this way:
# - The config is copied to a scratch directory: LinuxCNC writes its
#   parameter file next to the INI, and the repository must stay clean.
# - uspace rtapi_app refuses to run as root unless RTAPI_UID names an
#   unprivileged user; it then creates its socket (RTAPI_FIFO_PATH) with that
#   user's file rights, so the socket goes into that user's home.
# - LinuxCNC allows one instance per host (/tmp/linuxcnc.lock); a stale lock
#   left by a killed run is removed, a live instance makes this script fail
#   (linuxcnc would otherwise silently shut the other instance down).
# - linuxcnc runs in its own session (setsid): after it exits, anything left
#   of *this* run (milltask, io, halsampler ...) is found by session id and
#   stopped, after a regular `halrun -U` (rtapi_app has a session of its own;
#   the lock file still being there tells that it was not unloaded).
set -u

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
lock=/tmp/linuxcnc.lock
rundir=""
lpid=""
sid=""

say() { echo "[run_program] $*"; }
die() { say "ERROR: $*"; exit 2; }

# live (non-zombie) processes whose command name is one of the arguments
running() { ps -eo stat=,comm= | awk -v names=" $* " '$1 !~ /^Z/ && index(names, " " $2 " ") {f=1} END {exit !f}'; }

# live processes of linuxcnc's session (setsid made its pid the session id)
leftovers() {
    [ -n "$sid" ] || return 0
    ps -o pid=,stat= -s "$sid" 2>/dev/null | awk '$2 !~ /^Z/ {printf "%s ", $1}'
}

cleanup() {
    local rc=$? i left=""
    # interrupted while LinuxCNC runs: let linuxcnc shut itself down first
    # (timeout forwards the TERM to it), for at most 25 s
    if [ -n "$lpid" ] && kill -0 "$lpid" 2>/dev/null; then
        say "stopping LinuxCNC"
        kill -TERM "$lpid" 2>/dev/null
        for i in $(seq 50); do kill -0 "$lpid" 2>/dev/null || break; sleep 0.5; done
    fi
    if [ -n "$lpid" ]; then
        # processes that are just exiting get 3 s
        for i in $(seq 10); do
            left=$(leftovers)
            [ -z "$left" ] && [ ! -e "$lock" ] && break
            sleep 0.3
        done
        if [ -n "$left" ] || [ -e "$lock" ]; then
            say "LinuxCNC left over (processes: ${left:-none}); running halrun -U"
            timeout 30 halrun -U >/dev/null 2>&1
            sleep 0.5
            left=$(leftovers)
            if [ -n "$left" ]; then
                say "killing leftover processes of this run: $left"
                kill -TERM $left 2>/dev/null; sleep 1
                left=$(leftovers)
                [ -n "$left" ] && kill -KILL $left 2>/dev/null
            fi
            rm -f "$lock"
        fi
    fi
    if [ -n "$rundir" ]; then
        if [ "${SERVOTWIN_KEEP_RUNDIR:-0}" = 1 ] || [ "$rc" -ne 0 ]; then
            say "run directory kept: $rundir"
        else
            rm -rf "$rundir"
        fi
    fi
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# ---- arguments and prerequisites ---------------------------------------------
[ $# -eq 2 ] || { echo "usage: $0 PROGRAM.nc OUT_TRACE.txt" >&2; exit 2; }
program=$(realpath -e -- "$1" 2>/dev/null) || die "program not found: $1"
out=$(realpath -m -- "$2")
[ -d "$(dirname "$out")" ] || die "directory of $2 does not exist"
rm -f -- "$out"
command -v linuxcnc >/dev/null || die "linuxcnc not installed (Debian 12: apt-get install linuxcnc-uspace)"
/usr/bin/python3 -c 'import linuxcnc' 2>/dev/null || die "/usr/bin/python3 cannot import the linuxcnc module"
timeout_s=${SERVOTWIN_TIMEOUT:-120}
overall=${SERVOTWIN_OVERALL_TIMEOUT:-$(( ${timeout_s%.*} + 60 ))}

# ---- one LinuxCNC per host ---------------------------------------------------
if [ -e "$lock" ]; then
    running milltask rtapi_app linuxcncsvr io && die "another LinuxCNC is running (lock $lock); not touching it"
    say "removing stale $lock"
    rm -f "$lock"
fi

# ---- scratch run directory with a copy of the config ----------------------
rundir=$(mktemp -d "${TMPDIR:-/tmp}/servotwin-lcnc.XXXXXX") || { rundir=""; die "mktemp failed"; }
chmod 755 "$rundir"
cp -p "$here/servotwin_sim.hal" "$here/st_display.py" "$here/tool.tbl" "$rundir/" \
    && cp "${SERVOTWIN_INI:-$here/servotwin_sim.ini}" "$rundir/servotwin_sim.ini" \
    || die "copying the config failed"
: > "$rundir/sim.var"

# ---- realtime user ---------------------------------------------------------
if [ "$(id -u)" -eq 0 ]; then
    user=${SERVOTWIN_LCNC_USER:-linuxcnc-sim}
    if ! id -u "$user" >/dev/null 2>&1; then
        say "creating system user $user for rtapi_app (it refuses to run as root)"
        useradd --system --create-home --home-dir "/var/lib/$user" \
                --shell /usr/sbin/nologin "$user" || die "useradd $user failed"
    fi
    uhome=$(getent passwd "$user" | cut -d: -f6)
    install -d -o "$user" -m 755 "$uhome" || die "cannot create $uhome"
    export RTAPI_UID=$(id -u "$user")
    export RTAPI_FIFO_PATH="$uhome/.rtapi_fifo"
else
    export RTAPI_FIFO_PATH="$rundir/.rtapi_fifo"
fi

export SERVOTWIN_PROGRAM="$program"
export SERVOTWIN_TRACE="$rundir/trace.txt"
export SERVOTWIN_TIMEOUT="$timeout_s"
unset DISPLAY WAYLAND_DISPLAY   # no X: linuxcnc would try popups

# ---- run ---------------------------------------------------------------------
say "program $program"
say "LinuxCNC config copied to $rundir; overall timeout ${overall} s"
t0=$(date +%s.%N)
# HOME=rundir: on failure linuxcnc copies its logs to $HOME/linuxcnc_*.txt.
# setsid execs in place here (a background job of a script is no process
# group leader), so linuxcnc's session id is $lpid; checked, in case not.
HOME="$rundir" setsid --wait timeout --kill-after=15 "$overall" \
    linuxcnc -r "$rundir/servotwin_sim.ini" < /dev/null &
lpid=$!
sleep 0.2
[ "$(ps -o sid= -p "$lpid" 2>/dev/null | tr -d ' ')" = "$lpid" ] && sid=$lpid
wait "$lpid"
rc=$?
t1=$(date +%s.%N)
say "linuxcnc exited with status $rc after $(awk "BEGIN{printf \"%.1f\", $t1 - $t0}") s"

[ $rc -eq 124 ] && say "ERROR: overall timeout (${overall} s) hit"
if [ $rc -eq 0 ]; then
    [ -s "$rundir/trace.txt" ] || { say "ERROR: empty trace"; exit 1; }
    if grep -q '^overrun' "$rundir/trace.txt"; then
        say "ERROR: trace has overrun lines (samples lost)"; exit 1
    fi
    mv "$rundir/trace.txt" "$out" || exit 1
    say "trace: $out ($(wc -l < "$out") samples)"
    exit 0
fi
[ -s "$rundir/trace.txt" ] && say "partial trace left in $rundir/trace.txt"
exit 1
