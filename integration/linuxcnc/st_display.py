#!/usr/bin/python3
# servotwin LinuxCNC rig: the [DISPLAY] program. No GUI: it turns the
# machine on, homes, sends optional MDI commands, runs ONE program while
# halsampler records the trace, and exits (0 = program ran to its end).
#
# /usr/bin/python3 on purpose: the `linuxcnc` module is installed for the
# system Python only (a pyenv/venv python3 on PATH would not find it).
#
# Settings: [SERVOTWIN] in the INI, overridden by environment variables
#   SERVOTWIN_PROGRAM, SERVOTWIN_TRACE, SERVOTWIN_TIMEOUT, SERVOTWIN_MDI
#   ('|'-separated, since ';' starts a G-code comment), SERVOTWIN_PRE_ROLL,
#   SERVOTWIN_SETTLE.
# Never hangs: everything is bounded by TIMEOUT (default 120 s); on timeout
# or error it aborts, stops the trace and exits non-zero with a message.
# linuxcnc shuts the rest of LinuxCNC down when this script exits.

import os
import signal
import subprocess
import sys
import time

import linuxcnc

T0 = time.monotonic()


def log(msg):
    print("[st_display %7.3f] %s" % (time.monotonic() - T0, msg), flush=True)


class Failure(Exception):
    pass


def ini_path_from_argv(argv):
    for i, a in enumerate(argv[:-1]):
        if a == "-ini":
            return os.path.abspath(argv[i + 1])
    raise Failure("usage: st_display.py -ini FILE (started by linuxcnc)")


def setting(ini, key, default):
    env = os.environ.get("SERVOTWIN_" + key)
    if env is not None and env != "":
        return env
    val = ini.find("SERVOTWIN", key)
    return default if val is None or val == "" else val


def halcmd(*args):
    r = subprocess.run(["halcmd"] + list(args), capture_output=True, text=True, timeout=10)
    if r.returncode != 0:
        raise Failure("halcmd %s failed: %s" % (" ".join(args), (r.stderr or r.stdout).strip()))
    return r.stdout.strip()


class Rig:
    def __init__(self, timeout):
        self.deadline = T0 + timeout
        self.timeout = timeout
        self.s = None
        self.c = None
        self.e = None
        self.errors = []

    def left(self):
        return self.deadline - time.monotonic()

    def check_deadline(self, what):
        if self.left() <= 0:
            raise Failure("timeout (%.0f s) while %s" % (self.timeout, what))

    def drain_errors(self):
        """Print every message of LinuxCNC's error channel; remember errors."""
        while True:
            m = self.e.poll()
            if not m:
                return
            kind, text = m
            if kind in (linuxcnc.NML_ERROR, linuxcnc.OPERATOR_ERROR):
                log("LinuxCNC ERROR: %s" % text)
                self.errors.append(text)
            else:
                log("LinuxCNC message: %s" % text)

    def poll(self):
        self.s.poll()
        self.drain_errors()

    def wait(self, what, cond, period=0.01):
        while True:
            self.poll()
            if cond():
                return
            if self.errors:
                raise Failure("LinuxCNC reported an error while %s: %s" % (what, self.errors[-1]))
            self.check_deadline(what)
            time.sleep(period)

    def connect(self):
        # task and its NML channels come up after the HAL files ran
        while True:
            try:
                self.s = linuxcnc.stat()
                self.c = linuxcnc.command()
                self.e = linuxcnc.error_channel()
                self.s.poll()
                return
            except linuxcnc.error:
                self.check_deadline("connecting to LinuxCNC")
                time.sleep(0.1)

    def set_mode(self, mode):
        if self.s.task_mode != mode:
            self.c.mode(mode)
            self.c.wait_complete(max(0.1, min(5.0, self.left())))
        self.wait("switching mode", lambda: self.s.task_mode == mode)


def main():
    ini_path = ini_path_from_argv(sys.argv)
    ini_dir = os.path.dirname(ini_path)
    ini = linuxcnc.ini(ini_path)
    timeout = float(setting(ini, "TIMEOUT", "120"))
    program = setting(ini, "PROGRAM", "")
    trace = setting(ini, "TRACE", "trace.txt")
    pre_roll = float(setting(ini, "PRE_ROLL", "0.05"))
    settle = float(setting(ini, "SETTLE", "0.2"))
    env_mdi = os.environ.get("SERVOTWIN_MDI")
    if env_mdi:
        mdi = [m.strip() for m in env_mdi.split("|") if m.strip()]
    else:
        mdi = [m.strip() for m in (ini.findall("SERVOTWIN", "MDI") or []) if m.strip()]
    if not program:
        raise Failure("no program: set SERVOTWIN_PROGRAM or [SERVOTWIN]PROGRAM")
    program = os.path.join(ini_dir, program)
    trace = os.path.join(ini_dir, trace)
    if not os.path.isfile(program):
        raise Failure("program not found: %s" % program)
    joints = int(ini.find("KINS", "JOINTS"))

    rig = Rig(timeout)
    sampler = None
    ok = False
    try:
        rig.connect()
        log("connected; program %s, trace %s, timeout %.0f s" % (program, trace, timeout))
        rig.drain_errors()
        rig.errors.clear()  # nothing has been commanded yet

        rig.c.state(linuxcnc.STATE_ESTOP_RESET)
        rig.wait("resetting e-stop", lambda: rig.s.task_state == linuxcnc.STATE_ESTOP_RESET)
        rig.c.state(linuxcnc.STATE_ON)
        rig.wait("turning the machine on", lambda: rig.s.task_state == linuxcnc.STATE_ON)
        log("machine on")

        rig.set_mode(linuxcnc.MODE_MANUAL)
        rig.c.home(-1)  # all joints, by HOME_SEQUENCE; no switches: instant
        rig.wait("homing", lambda: all(rig.s.homed[j] for j in range(joints)))
        log("homed")

        if mdi:
            rig.set_mode(linuxcnc.MODE_MDI)
            for cmd in mdi:
                log("MDI %s" % cmd)
                rig.c.mdi(cmd)
                rig.c.wait_complete(max(0.1, min(10.0, rig.left())))
                rig.wait("MDI %s" % cmd, lambda: rig.s.interp_state == linuxcnc.INTERP_IDLE)

        # trace: halsampler attaches to the (disabled) sampler FIFO, then the
        # sampler is enabled just before the program starts
        sampler = subprocess.Popen(["halsampler", "-t", "-c", "0", trace])
        time.sleep(0.2)
        if sampler.poll() is not None:
            raise Failure("halsampler exited at start (status %s)" % sampler.returncode)
        halcmd("setp", "sampler.0.enable", "1")
        time.sleep(pre_roll)

        rig.set_mode(linuxcnc.MODE_AUTO)
        rig.c.program_open(program)
        rig.c.wait_complete(max(0.1, min(10.0, rig.left())))
        rig.poll()
        if rig.errors:
            raise Failure("LinuxCNC could not open the program: %s" % rig.errors[-1])
        t_run = time.monotonic()
        rig.c.auto(linuxcnc.AUTO_RUN, 0)
        log("program started")

        # done = interpreter idle, motion queue empty and in position, seen
        # for a few consecutive polls (a very short program may finish before
        # the first poll sees it running)
        idle_polls = 0
        while True:
            rig.poll()
            if rig.errors:
                time.sleep(0.1)  # let the status catch up for the line number
                rig.s.poll()
                where = " (line %d)" % rig.s.read_line if rig.s.read_line > 0 else ""
                raise Failure("LinuxCNC reported an error during the program%s: %s"
                              % (where, rig.errors[-1]))
            if rig.s.task_state != linuxcnc.STATE_ON:
                raise Failure("machine turned off during the program (task_state %d)" % rig.s.task_state)
            if rig.s.interp_state == linuxcnc.INTERP_PAUSED or rig.s.paused:
                raise Failure("program paused at line %d (M0/M1/M60?): nobody can resume it"
                              % rig.s.motion_line)
            idle = (rig.s.interp_state == linuxcnc.INTERP_IDLE and rig.s.queue == 0
                    and rig.s.inpos and rig.s.exec_state == linuxcnc.EXEC_DONE)
            idle_polls = idle_polls + 1 if idle else 0
            if idle_polls >= 5 and time.monotonic() - t_run > 0.2:
                break
            rig.check_deadline("running the program")
            time.sleep(0.01)
        log("program finished after %.3f s" % (time.monotonic() - t_run))
        time.sleep(settle)
        ok = True
    except Failure as ex:
        log("FAILED: %s" % ex)
        if rig.c is not None:
            try:
                rig.c.abort()
            except Exception:
                pass
    finally:
        if sampler is not None:
            ok = stop_trace(sampler, rig) and ok
    return 0 if ok else 1


def stop_trace(sampler, rig):
    """Disable the sampler, let halsampler empty the FIFO, stop it (SIGTERM:
    halsampler flushes its file and exits 0)."""
    good = True
    try:
        halcmd("setp", "sampler.0.enable", "0")
        t = time.monotonic()
        while int(halcmd("getp", "sampler.0.curr-depth")) > 0:
            if time.monotonic() - t > 10:
                log("halsampler did not drain the FIFO in 10 s")
                good = False
                break
            time.sleep(0.02)
        overruns = int(halcmd("getp", "sampler.0.overruns"))
        if overruns:
            log("sampler FIFO overran %d times: samples were lost" % overruns)
            good = False
    except Exception as ex:
        log("stopping the trace: %s" % ex)
        good = False
    time.sleep(0.05)  # curr-depth counts the FIFO, halsampler may still print
    sampler.send_signal(signal.SIGTERM)
    try:
        rc = sampler.wait(5)
    except subprocess.TimeoutExpired:
        sampler.kill()
        rc = sampler.wait()
    if rc != 0:
        log("halsampler exited with status %s" % rc)
        good = False
    return good


if __name__ == "__main__":
    try:
        sys.exit(main())
    except Failure as ex:
        log("FAILED: %s" % ex)
        sys.exit(1)
