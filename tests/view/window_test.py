#!/usr/bin/env python3
"""Scripted test of rtr-view in a real window under its own Xvfb, driven by xdotool.

Usage: window_test.py RTR_VIEW SCENE
Exit 0: pass, 1: fail, 77: Xvfb or xdotool missing (CTest SKIP_RETURN_CODE).
"""
import ctypes
import ctypes.util
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

SKIP = 77
SIZE = (320, 240)  # lavapipe renders on the CPU: keep frames small


class Fail(Exception):
    pass


def check(cond, msg):
    if not cond:
        raise Fail(msg)
    print("ok:", msg, flush=True)


def start_xvfb(fbdir):
    # -displayfd lets the server pick a free display number and report it, so parallel runs never collide.
    # -fbdir: the screen is also an XWD file there, read by screen_pixels().
    r, w = os.pipe()
    proc = subprocess.Popen(["Xvfb", "-displayfd", str(w), "-screen", "0", "640x480x24", "-nolisten", "tcp",
                             "-fbdir", fbdir], pass_fds=(w,), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    os.close(w)
    with os.fdopen(r) as f:
        num = f.readline().strip()
    if not num:
        proc.kill()
        raise Fail("Xvfb did not report a display number")
    return proc, ":" + num


def screen_pixels(fbdir, x0, y0, x1, y1):
    """(r, g, b) of the screen's pixels in [x0, x1) x [y0, y1), from Xvfb's XWD frame buffer file."""
    import struct
    with open(os.path.join(fbdir, "Xvfb_screen0"), "rb") as f:
        data = f.read()
    h = struct.unpack(">25I", data[:100])
    header, byte_order, bpp, bpl, ncolors = h[0], h[7], h[11], h[12], h[19]
    if bpp != 32:
        raise Fail(f"unexpected XWD format: {bpp} bits per pixel")
    base = header + 12 * ncolors
    out = []
    for y in range(y0, y1):
        row = base + y * bpl
        for x in range(x0, x1):
            b, g, r = data[row + 4 * x: row + 4 * x + 3] if byte_order == 0 else data[row + 4 * x + 1: row + 4 * x + 4][::-1]
            out.append((r, g, b))
    return out


def wm_iconify(display, win, iconic):
    """Iconifies (or restores) a window the way a window manager would, through libX11."""
    x = ctypes.CDLL(ctypes.util.find_library("X11") or "libX11.so.6")
    x.XOpenDisplay.restype = ctypes.c_void_p
    x.XOpenDisplay.argtypes = [ctypes.c_char_p]
    x.XInternAtom.restype = ctypes.c_ulong
    x.XInternAtom.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int]
    x.XChangeProperty.argtypes = [ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_ulong, ctypes.c_int,
                                  ctypes.c_int, ctypes.c_void_p, ctypes.c_int]
    for f in (x.XMapWindow, x.XUnmapWindow):
        f.argtypes = [ctypes.c_void_p, ctypes.c_ulong]
    x.XSync.argtypes = [ctypes.c_void_p, ctypes.c_int]
    x.XCloseDisplay.argtypes = [ctypes.c_void_p]
    d = x.XOpenDisplay(display.encode())
    if not d:
        raise Fail(f"cannot open {display} through libX11")
    wm_state = x.XInternAtom(d, b"WM_STATE", 0)
    data = (ctypes.c_long * 2)(3 if iconic else 1, 0)  # IconicState / NormalState, no icon window
    x.XChangeProperty(d, win, wm_state, wm_state, 32, 0, data, 2)  # format 32 takes longs; 0: PropModeReplace
    (x.XUnmapWindow if iconic else x.XMapWindow)(d, win)
    x.XSync(d, 0)
    x.XCloseDisplay(d)


class Viewer:
    """rtr-view with stdout/stderr collected by threads (so the pipes never fill up)."""

    def __init__(self, args, env):
        self.proc = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.out, self.err = [], []
        self.lock = threading.Lock()
        for stream, sink in ((self.proc.stdout, self.out), (self.proc.stderr, self.err)):
            threading.Thread(target=self._pump, args=(stream, sink), daemon=True).start()

    def _pump(self, stream, sink):
        for line in stream:
            with self.lock:
                sink.append(line.rstrip("\n"))

    def lines(self, which):
        with self.lock:
            return list(self.out if which == "out" else self.err)

    def wait_line(self, which, pattern, start=0, timeout=20.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for line in self.lines(which)[start:]:
                m = re.search(pattern, line)
                if m:
                    return m
            if self.proc.poll() is not None:
                break
            time.sleep(0.02)
        raise Fail(f"no line matching {pattern!r} on std{which} (alive: {self.proc.poll() is None})")


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    viewer_bin, scene = sys.argv[1], sys.argv[2]
    for tool in ("Xvfb", "xdotool"):
        if not shutil.which(tool):
            print(f"skip: {tool} is not installed (tools/setup.sh installs it)")
            return SKIP

    t0 = time.monotonic()
    fbtmp = tempfile.TemporaryDirectory(prefix="rtr-xvfb-")  # removed when main returns
    fbdir = fbtmp.name
    xvfb, display = start_xvfb(fbdir)
    # The panel's layout file (imgui.ini) goes to a fresh config folder: runs never see each other's.
    env = dict(os.environ, DISPLAY=display, RTR_VALIDATION="1", XDG_CONFIG_HOME=os.path.join(fbdir, "config"))
    viewer = None
    try:
        def xdo(*args):
            subprocess.run(["xdotool", *map(str, args)], env=env, check=True, capture_output=True, timeout=30)

        def xdo_out(*args):
            return subprocess.run(["xdotool", *map(str, args)], env=env, check=True, capture_output=True, text=True,
                                  timeout=30).stdout.strip()

        # --wait-textures: every frame compared has the textures (the panel test covers a deferred load).
        viewer = Viewer([viewer_bin, scene, "--validation", "--wait-textures", "--size", f"{SIZE[0]}x{SIZE[1]}",
                         "--mosaic", "off"], env)
        speed = float(viewer.wait_line("err", r"move speed ([0-9.eE+-]+) units/s").group(1))
        win = xdo_out("search", "--sync", "--name", "^rtr-view").split()[0]
        # No window manager: give the window the keyboard focus and put the pointer over it ourselves.
        xdo("windowfocus", "--sync", win)
        xdo("mousemove", "--window", win, SIZE[0] // 2, SIZE[1] // 2)

        def title():
            return xdo_out("getwindowname", win)

        # The title is rewritten every 0.25 s from the render loop; wait until the first frames are out.
        end = time.monotonic() + 30
        while "CPU" not in title():
            if time.monotonic() > end or viewer.proc.poll() is not None:
                raise Fail("the viewer did not render its first frames")
            time.sleep(0.05)
        print(f"started in {time.monotonic() - t0:.1f} s on {display}; move speed {speed:g} units/s", flush=True)
        # The settings panel starts shown and takes the clicks over it: F1 hides it for the key and mouse checks.
        xdo("key", "F1")
        time.sleep(0.5)

        def pose():
            n = len(viewer.lines("out"))
            xdo("key", "c")
            m = viewer.wait_line("out", r"^--camera (\S+)$", start=n)
            return [float(v) for v in m.group(1).split(",")]

        def forward(p):
            yaw, pitch = math.radians(p[3]), math.radians(p[4])
            return (-math.sin(yaw) * math.cos(pitch), math.sin(pitch), -math.cos(yaw) * math.cos(pitch))

        def hold(keys, seconds):
            """Holds keys for `seconds`; returns (displacement, forward at start, measured hold time)."""
            p0 = pose()
            start = time.monotonic()
            xdo("keydown", *keys)
            time.sleep(seconds)
            xdo("keyup", *reversed(keys))
            held = time.monotonic() - start
            p1 = pose()
            check(abs(p1[3] - p0[3]) < 1e-4 and abs(p1[4] - p0[4]) < 1e-4, f"holding {'+'.join(keys)} leaves yaw/pitch alone")
            return [b - a for a, b in zip(p0[:3], p1[:3])], forward(p0), held

        def check_move(keys, seconds, expected_speed, sign=1):
            d, fwd, held = hold(keys, seconds)
            dist = math.sqrt(sum(c * c for c in d))
            want = expected_speed * held
            cos = sign * sum(a * b for a, b in zip(d, fwd)) / dist if dist > 0 else 0.0
            print(f"  {'+'.join(keys)} held {held:.3f} s: moved {dist:.4f}, expected {want:.4f} "
                  f"({dist / want:.2f}x), cos to view direction {cos:.4f}", flush=True)
            check(abs(dist / want - 1) <= 0.35, f"{'+'.join(keys)} moves speed x time within 35 %")
            check(cos > 0.99, f"{'+'.join(keys)} moves along the view direction")
            return dist / held

        # Movement: W at base speed, Shift+W five times as fast (measured, not assumed from the other run).
        v_walk = check_move(["w"], 1.0, speed)
        v_fast = check_move(["shift", "w"], 1.0, speed * 5)
        check(v_fast > 3 * v_walk, f"Shift is faster ({v_fast / v_walk:.2f}x W)")

        # F frames the whole scene: one fixed pose, whatever the camera did before.
        xdo("key", "f")
        time.sleep(0.3)
        framed = pose()
        hold(["d"], 0.3)
        moved = pose()
        xdo("key", "f")
        time.sleep(0.3)
        again = pose()
        check(moved != framed and again == framed, f"F frames the scene ({framed})")

        # Mouse-look: RMB on, motion turns the camera; RMB off, motion does not.
        p0 = pose()
        xdo("click", "3")
        time.sleep(0.3)
        for _ in range(6):
            xdo("mousemove_relative", "--", 15, 8)
            time.sleep(0.1)
        time.sleep(0.3)
        p1 = pose()
        check(abs(p1[3] - p0[3]) > 1.0 and abs(p1[4] - p0[4]) > 1.0,
              f"mouse-look on: yaw {p0[3]:.2f} -> {p1[3]:.2f}, pitch {p0[4]:.2f} -> {p1[4]:.2f}")
        check(p1[3] < p0[3] and p1[4] < p0[4], "mouse right/down turns right/down (yaw and pitch decrease)")
        xdo("click", "3")
        time.sleep(0.3)
        for _ in range(6):
            xdo("mousemove_relative", "--", -15, -8)
            time.sleep(0.1)
        time.sleep(0.3)
        p2 = pose()
        check(p2[3] == p1[3] and p2[4] == p1[4], "mouse-look off: motion leaves yaw/pitch alone")

        # View modes and mosaic: every key must reach the renderer (the title names the mode) without errors.
        modes = {"1": "shaded", "2": "mip level", "3": "linear depth", "4": "depth derivatives", "5": "normal",
                 "6": "view dir", "7": "light dir", "8": "BRDF D", "9": "BRDF F", "0": "BRDF G", "minus": "diffuse",
                 "equal": "specular"}
        mosaics = ["compute", "graphics", "off"]  # M cycles off -> compute -> graphics -> off

        def wait_title(part):
            end = time.monotonic() + 10
            while time.monotonic() < end:
                t = title()
                if f"| {part} |" in t:
                    return t
                time.sleep(0.05)
            raise Fail(f"title never showed {part!r} (last: {t!r})")

        for key, name in modes.items():
            xdo("key", key)
            wait_title(name)
        check(True, f"{len(modes)} view modes reach the renderer")
        for name in mosaics:
            xdo("key", "m")
            wait_title(f"mosaic {name}")
        check(True, "M cycles the mosaic compute -> graphics -> off")
        xdo("key", "1")
        wait_title("shaded")

        # F1: the settings panel is drawn over the frame (top-left); F1 again removes it, pixel for pixel.
        # The window sits at the screen's origin (no window manager).
        # It starts collapsed: its title bar, from (8, 8), about 19 pixels high.
        before = screen_pixels(fbdir, 10, 10, 120, 24)
        xdo("key", "F1")
        time.sleep(1.0)
        shown = screen_pixels(fbdir, 10, 10, 120, 24)
        changed = sum(1 for a, b in zip(before, shown) if a != b)
        check(changed > 0.5 * len(before), f"F1 draws the panel into the frame ({changed} of {len(before)} pixels changed)")
        xdo("key", "F1")
        time.sleep(1.0)
        check(screen_pixels(fbdir, 10, 10, 120, 24) == before, "F1 again removes it: the same pixels as before (the camera is still)")

        # X: trace the view with the renderer's model and show the error map; the title gives mean and max.
        frame = screen_pixels(fbdir, 0, 0, SIZE[0], SIZE[1])
        xdo("key", "x")
        end, m = time.monotonic() + 30, None
        while time.monotonic() < end and not m:
            m = re.search(r"error map, raster vs CPU trace: mean ([0-9.]+), max ([0-9]+)", title())
            time.sleep(0.1)
        check(m is not None and 0 <= float(m.group(1)) <= float(m.group(2)) <= 255,
              f"X shows the error map with its mean and max ({m.group(0) if m else title()!r})")
        time.sleep(0.5)
        check(screen_pixels(fbdir, 0, 0, SIZE[0], SIZE[1]) != frame, "the error map replaces the raster image")
        xdo("key", "x")
        end, hidden = time.monotonic() + 30, False  # polled: a loaded machine may take over a second a frame
        while time.monotonic() < end and not hidden:
            time.sleep(0.2)
            hidden = "error map" not in title() and screen_pixels(fbdir, 0, 0, SIZE[0], SIZE[1]) == frame
        check(hidden, "X again hides it")

        # 100 resizes as fast as xdotool can issue them (one process, chained commands).
        t_resize = time.monotonic()
        chain = []
        for i in range(100):
            chain += ["windowsize", win, 160 + (i * 37) % 240, 120 + (i * 53) % 180, "sleep", "0.01"]
        chain += ["windowsize", "--sync", win, SIZE[0], SIZE[1]]
        xdo(*chain)
        time.sleep(0.5)
        check(viewer.proc.poll() is None, f"alive after 100 resizes ({time.monotonic() - t_resize:.1f} s)")
        geom = xdo_out("getwindowgeometry", win)
        check(f"{SIZE[0]}x{SIZE[1]}" in geom, "the window is back at its size")

        # Minimise and restore. There is no window manager to answer `xdotool windowminimize`, so do what
        # one does on iconify: mark WM_STATE Iconic (GLFW reads that) and unmap; restore reverses both.
        before = title()
        wm_iconify(display, int(win), True)
        time.sleep(0.5)
        paused_from = title()
        time.sleep(1.0)
        check(viewer.proc.poll() is None, "alive while minimised")
        # The title carries the smoothed CPU frame time, rewritten every 0.25 s while frames are rendered.
        check(title() == paused_from, "minimised: rendering pauses (the title stops changing)")
        wm_iconify(display, int(win), False)
        xdo("windowfocus", "--sync", win)
        xdo("mousemove", "--window", win, SIZE[0] // 2, SIZE[1] // 2)
        time.sleep(0.5)
        check(viewer.proc.poll() is None and title() not in (paused_from, before), "restored: rendering resumes")
        # Still rendering: movement is integrated once per rendered frame, so it only happens if frames do.
        check_move(["s"], 0.6, speed, sign=-1)  # S: backwards
    except Fail as e:
        print("FAIL:", e, flush=True)
        return finish(viewer, xvfb, ok=False, t0=t0, xdo=None)
    return finish(viewer, xvfb, ok=True, t0=t0, xdo=xdo)


def finish(viewer, xvfb, ok, t0, xdo):
    try:
        if viewer and viewer.proc.poll() is None and xdo:
            xdo("key", "Escape")
            try:
                rc = viewer.proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                rc = None
            if rc != 0:
                print(f"FAIL: Esc should quit with exit code 0, got {rc}", flush=True)
                ok = False
            else:
                print("ok: Esc quits with exit code 0", flush=True)
        elif viewer and viewer.proc.poll() is not None:
            print(f"viewer exited early with code {viewer.proc.returncode}", flush=True)
            ok = False
        if viewer and viewer.proc.poll() is None:
            viewer.proc.kill()
            viewer.proc.wait()
        if viewer:
            time.sleep(0.1)  # let the reader threads drain the pipes
            err = viewer.lines("err")
            bad = [l for l in err if "[vulkan" in l]
            if bad:
                print(f"FAIL: {len(bad)} validation message(s) on stderr:", flush=True)
                ok = False
            else:
                print("ok: no validation messages on stderr", flush=True)
            print("--- viewer stderr ---\n" + "\n".join(err[-60:]), flush=True)
    finally:
        xvfb.terminate()
        xvfb.wait()
    print(f"{'PASS' if ok else 'FAIL'} in {time.monotonic() - t0:.1f} s", flush=True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
