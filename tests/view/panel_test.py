#!/usr/bin/env python3
"""The windowed viewer's settings panel, orbit camera and dropped files, under its own Xvfb (xdotool).

Usage: panel_test.py RTR_VIEW SCENE_DIR   (SCENE_DIR holds temple.rtrscene and its temple-tex folder)
Exit 0: pass, 1: fail, 77: Xvfb or xdotool missing. The viewer runs with the test-only options --test-ui,
which prints each panel widget's rectangle ("ui ID x0 y0 x1 y1"), and --test-drop FILE: paths written to FILE
are handed to the window's drop callback (xdotool cannot drag files).
"""
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

from window_test import SKIP, Fail, Viewer, check, finish, screen_pixels, start_xvfb

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from pngread import read_png  # noqa: E402

SIZE = (480, 360)


def main():
    if len(sys.argv) < 3:
        print(__doc__)
        return 2
    viewer_bin, assets = sys.argv[1], sys.argv[2]
    for tool in ("Xvfb", "xdotool"):
        if not shutil.which(tool):
            print(f"skip: {tool} is not installed (tools/setup.sh installs it)")
            return SKIP
    t0 = time.monotonic()
    tmp = tempfile.TemporaryDirectory(prefix="rtr-panel-")
    fbdir = os.path.join(tmp.name, "fb")
    os.mkdir(fbdir)
    # The scene is copied: the panel's screenshots are written beside it.
    scenes = os.path.join(tmp.name, "scenes")
    os.mkdir(scenes)
    shutil.copy(os.path.join(assets, "temple.rtrscene"), scenes)
    shutil.copytree(os.path.join(assets, "temple-tex"), os.path.join(scenes, "temple-tex"))
    scene = os.path.join(scenes, "temple.rtrscene")
    config = os.path.join(tmp.name, "config")
    drop_file = os.path.join(tmp.name, "drop.txt")
    # A second file on the command line, for Right (the next file).
    second = os.path.join(tmp.name, "second.obj")
    with open(second, "w") as f:
        f.write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    xvfb, display = start_xvfb(fbdir)
    env = dict(os.environ, DISPLAY=display, RTR_VALIDATION="1", XDG_CONFIG_HOME=config)
    viewer = None
    try:
        def xdo(*args):
            subprocess.run(["xdotool", *map(str, args)], env=env, check=True, capture_output=True, timeout=30)

        def xdo_out(*args):
            return subprocess.run(["xdotool", *map(str, args)], env=env, check=True, capture_output=True, text=True,
                                  timeout=30).stdout.strip()

        viewer = Viewer([viewer_bin, scene, "--validation", "--orbit", "--timings", "--size", f"{SIZE[0]}x{SIZE[1]}",
                         "--test-ui", "--test-drop", drop_file, "--env", "sky", second], env)
        viewer.wait_line("err", r"move speed")
        # The textures load while frames go on (the materials show their factors meanwhile): every frame this
        # test compares comes after they are in.
        viewer.wait_line("err", r"rtr-view: 13 textures in\b")
        # --timings in the window: the start-up phases tile the time to the first frame on screen.
        viewer.wait_line("err", r"^  total from process start ")
        err = viewer.lines("err")
        rows = {}
        for line in err[err.index("rtr-view: start-up phases (ms):") + 1:]:
            name, ms = line.strip().rsplit(None, 1)
            rows[name] = float(ms)
            if name == "total from process start":
                break
        total = rows.pop("total from process start")
        check(rows.pop("sum of the critical path's phases", None) is not None, f"a critical path's sum ({sorted(rows)})")
        # The scene file read ran on its own thread beside the device's and the window's start, the pipelines
        # on theirs beside the scene's upload: their rows are marked so, lie within the spans they ran in,
        # and are not part of the critical path's sum.
        read = "scene file read (beside instance, device and window)"
        beside = {n: v for n, v in rows.items() if " (beside " in n}
        path = {n: v for n, v in rows.items() if n not in beside}
        upload = "geometry to the GPU, swapchain"
        for want in ("instance and device", "window, surface and panel", "waiting for the scene file read",
                     upload, "waiting for the pipelines", "first frame (record, GPU, present)"):
            check(want in path, f"the start-up phases have '{want}' ({sorted(rows)})")
        ahead = [n for n in beside if re.match(r"pipelines made ahead \([1-9]\d*, \d+ from the cache\) \(beside the scene upload\)$", n)]
        check(sorted(beside) == sorted([read] + ahead) and len(ahead) == 1,
              f"the scene file read and the pipelines made ahead are the rows beside the others ({sorted(beside)})")
        check(beside[read] <= path["instance and device"] + path["window, surface and panel"] +
              path["waiting for the scene file read"] + 1.0, f"the read lies within the span it ran beside ({rows})")
        check(not ahead or beside[ahead[0]] <= path[upload] + path["waiting for the pipelines"] + 1.0,
              f"the pipelines lie within the span they ran beside ({rows})")
        check(any(n.startswith("pipeline creation (") for n in path), "the start-up phases count the pipelines")
        check(all(v >= 0 for v in rows.values()) and abs(sum(path.values()) - total) <= 3.0,
              f"the critical path's phases add up to the total ({sum(path.values()):.1f} against {total:.1f} ms)")
        win = xdo_out("search", "--sync", "--name", "^rtr-view").split()[0]
        xdo("windowfocus", "--sync", win)

        def title():
            return xdo_out("getwindowname", win)

        def wait_title(part, timeout=15):
            end = time.monotonic() + timeout
            while time.monotonic() < end:
                if part in title():
                    return
                time.sleep(0.05)
            raise Fail(f"title never showed {part!r} (last: {title()!r})")

        def rect(widget):
            m = viewer.wait_line("out", rf"^ui {widget} (-?\d+) (-?\d+) (-?\d+) (-?\d+)$")
            return [int(v) for v in m.groups()]

        def latest_rect(widget):
            rect(widget)
            for line in reversed(viewer.lines("out")):
                if line.startswith(f"ui {widget} "):
                    return [int(v) for v in line.split()[2:]]

        def click(widget):
            x0, y0, x1, y1 = latest_rect(widget)
            xdo("mousemove", "--window", win, (x0 + x1) // 2, (y0 + y1) // 2)
            time.sleep(0.3)  # ImGui sees the hover in one frame and the click in the next
            xdo("click", "1")
            time.sleep(0.5)

        def settle(seconds=1.0):
            # Xvfb's frame buffer shows the cursor: park it off the window. Frames in flight: the screen shows
            # the newest state after a few frames.
            xdo("mousemove", SIZE[0] + 40, SIZE[1] + 40)
            time.sleep(seconds)

        def frame():
            return screen_pixels(fbdir, 0, 0, SIZE[0], SIZE[1])

        def pose():
            n = len(viewer.lines("out"))
            xdo("key", "c")
            p = viewer.wait_line("out", r"^--camera (\S+)$", start=n).group(1)
            t = viewer.wait_line("out", r"^orbit target (\S+) distance (\S+)$", start=n)
            return [float(v) for v in p.split(",")], [float(v) for v in t.group(1).split(",")], float(t.group(2))

        wait_title("CPU")
        # The panel starts collapsed to its title bar, the view free; its arrow opens it.
        bar = latest_rect("panel")
        h = bar[3] - bar[1]
        check(h < 40 and bar[2] - bar[0] < SIZE[0], f"the panel starts as a title bar only ({bar})")
        xdo("mousemove", "--window", win, bar[0] + h // 2, bar[1] + h // 2)
        time.sleep(0.3)
        xdo("click", "1")
        time.sleep(0.5)
        panel = latest_rect("lodbias")
        check(latest_rect("panel")[3] > bar[3] + 100, "a click on its arrow opens it")
        right = panel[2] + 20  # the view right of the panel
        check(right < SIZE[0] - 40, f"the panel leaves the right of the window free (widgets end at x={panel[2]})")
        # The panel's start-up section (scrolled into view) opens on the phases; closed and scrolled back after.
        xdo("mousemove", "--window", win, (panel[0] + panel[2]) // 2, SIZE[1] // 2)
        xdo("click", "--repeat", "15", "--delay", "30", "5")
        time.sleep(0.5)
        header = latest_rect("start-up")
        check(header[3] < SIZE[1], f"the start-up section's header scrolls into view ({header})")
        settle()
        closed = frame()
        click("start-up")
        settle()
        check(frame() != closed, "the panel's start-up section opens")
        check(rect("start-up:total")[1] > header[3], "it shows the time to the first frame under its header")
        click("start-up")
        xdo("mousemove", "--window", win, (panel[0] + panel[2]) // 2, SIZE[1] // 2)
        xdo("click", "--repeat", "15", "--delay", "30", "4")
        time.sleep(0.5)
        check(latest_rect("lodbias") == panel, "the panel scrolls back")

        # A view chosen in the panel's combo gives the same frame as its key.
        xdo("key", "5")
        wait_title("| normal |")
        xdo("key", "F1")
        settle()
        by_key = frame()
        xdo("key", "1")
        wait_title("| shaded |")
        settle()
        check(frame() != by_key, "the normal view differs from the shaded one")
        xdo("key", "F1")
        settle()
        click("mode")
        click("mode:5")
        wait_title("| normal |")
        xdo("key", "F1")
        settle()
        check(frame() == by_key, "the normal view chosen in the panel: the same frame as key 5, pixel for pixel")

        # The LOD bias slider changes the mip-level view; the drag on the panel leaves the orbit camera alone.
        xdo("key", "2")
        wait_title("| mip level |")
        xdo("key", "F1")
        settle()
        legend = latest_rect("legend")  # with the panel shown (F1 hides both); settled
        check(legend[0] < 20 and SIZE[1] - 40 < legend[3] <= SIZE[1] and legend[2] > legend[0] + 100,
              f"the mip-level view shows its legend at the bottom left ({legend})")
        before_view = screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1])
        p0 = pose()
        x0, y0, x1, y1 = latest_rect("lodbias")
        xdo("mousemove", "--window", win, (x0 + x1) // 2, (y0 + y1) // 2)
        time.sleep(0.3)
        xdo("mousedown", "1")
        time.sleep(0.3)
        for i in range(1, 6):
            xdo("mousemove", "--window", win, (x0 + x1) // 2 + i * (x1 - x0) // 10, (y0 + y1) // 2)
            time.sleep(0.15)
        xdo("mouseup", "1")
        settle()
        m = __import__("re").search(r"lod bias (-?[0-9.]+)", title())
        check(m and float(m.group(1)) > 1.0, f"dragging the slider raises the LOD bias ({m.group(0) if m else title()})")
        check(screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1]) != before_view, "the mip-level view changes with it")
        check(pose() == p0, "a drag on the panel does not move the camera")

        # The filter buttons: the nearest mip level changes the mip-level view; trilinear brings its frame back
        # (the texture descriptors rewritten between frames, under the validation layer).
        trilinear_view = screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1])
        click("nearest-mip")
        wait_title("| nearest-mip x1 |")
        settle()
        check(screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1]) != trilinear_view, "nearest-mip changes the mip-level view")
        click("trilinear")
        wait_title("| trilinear x1 |")
        settle()
        check(screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1]) == trilinear_view,
              "back to trilinear: the same mip-level view, pixel for pixel")

        # The screenshot button: a PNG beside the scene, without the panel, never overwriting.
        click("screenshot")
        shot1 = viewer.wait_line("err", r"rtr-view: saved (\S+)").group(1)
        n_err = len(viewer.lines("err"))
        click("screenshot")
        shot2 = viewer.wait_line("err", r"rtr-view: saved (\S+)", start=n_err).group(1)
        check(os.path.dirname(shot1) == scenes and shot1 != shot2,
              f"two screenshots beside the scene, the second a new file ({os.path.basename(shot1)}, {os.path.basename(shot2)})")
        xdo("key", "F1")
        settle()
        hidden = frame()
        w, h, rgb = read_png(shot1)
        px = [tuple(rgb[i:i + 3]) for i in range(0, len(rgb), 3)]
        check((w, h) == SIZE and px == hidden, "the screenshot holds the frame without the panel, pixel for pixel")
        xdo("key", "F1")
        settle()
        check(frame() != hidden, "the panel was on screen when the screenshot was taken")

        # Mip generation from the panel: the scene's GPU objects are rebuilt with the blit path (cleanly: the
        # validation layer is watching). The panel is still shown.
        n_err = len(viewer.lines("err"))
        click("blit")
        viewer.wait_line("err", r"rtr-view: mips \(blit\) [0-9.]+ ms GPU", start=n_err)
        wait_title("CPU")
        check(viewer.proc.poll() is None, "the blit radio button rebuilds the scene's mips")

        # Orbit: a left-drag over the view turns the camera about the target (which stays on the view axis, at
        # the same distance); scroll moves it to the target; a middle-drag pans both.
        xdo("key", "F1")
        xdo("key", "1")
        settle()
        (c0, t0_, d0) = pose()

        def drag(button, dx, dy):
            xdo("mousemove", "--window", win, SIZE[0] // 2, SIZE[1] // 2)
            time.sleep(0.3)
            xdo("mousedown", button)
            for i in range(1, 5):
                xdo("mousemove", "--window", win, SIZE[0] // 2 + dx * i // 4, SIZE[1] // 2 + dy * i // 4)
                time.sleep(0.15)
            xdo("mouseup", button)
            time.sleep(0.5)

        def forward(p):
            yaw, pitch = math.radians(p[3]), math.radians(p[4])
            return (-math.sin(yaw) * math.cos(pitch), math.sin(pitch), -math.cos(yaw) * math.cos(pitch))

        def close(a, b, tol):
            return all(abs(x - y) <= tol for x, y in zip(a, b))

        drag(1, 60, 20)
        (c1, t1, d1) = pose()
        f1 = forward(c1)
        aim = [c1[i] + f1[i] * d1 for i in range(3)]
        tol = 1e-3 * max(1.0, d0)
        check(abs(c1[3] - c0[3]) > 5 and abs(c1[4] - c0[4]) > 1, f"left-drag turns the camera (yaw {c0[3]:.1f} -> "
              f"{c1[3]:.1f}, pitch {c0[4]:.1f} -> {c1[4]:.1f})")
        check(close(c1[:3], c0[:3], tol) is False and close(t1, t0_, tol) and close(aim, t0_, tol) and abs(d1 - d0) < tol,
              f"about the target: it stays on the view axis at distance {d0:.3f} ({t0_} -> {t1})")
        xdo("click", "4")  # wheel up: towards the target
        time.sleep(0.5)
        (c2, t2, d2) = pose()
        check(d2 < d1 and close(t2, t1, tol) and c2[3:] == c1[3:], f"scroll moves towards the target ({d1:.3f} -> {d2:.3f})")
        drag(2, 40, 0)
        (c3, t3, d3) = pose()
        check(not close(t3, t2, tol) and abs(d3 - d2) < tol and c3[3:] == c2[3:], "middle-drag pans camera and target")
        xdo("key", "Home")
        time.sleep(0.5)
        check(pose()[0] == c0, "Home returns to the start pose")

        # Drops: a bad file keeps the scene and says why in the panel; a good one replaces the scene.
        bad = os.path.join(tmp.name, "bad.obj")
        with open(bad, "w") as f:
            f.write("v 0 0 0\nf 1 2 3\n")
        settle()  # the panel is hidden since the orbit checks
        kept = frame()

        def drop(path):
            with open(drop_file + ".tmp", "w") as f:
                f.write(path + "\n")
            os.rename(drop_file + ".tmp", drop_file)

        n_err = len(viewer.lines("err"))
        drop(bad)
        msg = viewer.wait_line("err", r"rtr-view: cannot load: (.*)", start=n_err).group(1)
        check("bad.obj" in msg, f"a bad drop is reported, naming the file ({msg})")
        settle()
        check(frame() == kept, "a bad drop keeps the scene on screen")
        xdo("key", "F1")
        check(rect("message")[3] > 0, "the panel shows the message")
        # A triangle far from the origin: F must frame it, whatever the pose.
        tri, far = os.path.join(tmp.name, "tri.obj"), (1000.0, 500.0, -700.0)
        with open(tri, "w") as f:
            f.write("".join(f"v {far[0] + x} {far[1] + y} {far[2]}\n" for x, y in ((-1, -1), (1, -1), (0, 1))) + "f 1 2 3\n")
        n_err = len(viewer.lines("err"))
        drop(tri)
        viewer.wait_line("err", r"rtr-view: loaded .*tri\.obj", start=n_err)
        viewer.wait_line("err", r"move speed", start=n_err)
        xdo("key", "F1")
        settle()
        check(frame() != kept, "a good drop replaces the scene")
        xdo("key", "Home")  # the dropped scene's start pose; then somewhere else, then F
        drag(1, -80, 30)
        xdo("key", "f")
        time.sleep(0.5)
        (cf, _, _) = pose()
        fwd = forward(cf)
        to = [far[i] - cf[i] for i in range(3)]
        dist = math.sqrt(sum(v * v for v in to))
        cos = sum(a * b for a, b in zip(fwd, to)) / dist
        check(cos > 0.999 and dist < 20, f"F frames the far triangle (distance {dist:.2f}, cos {cos:.5f})")
        # F5 reads the file again: an edited triangle (now far to the other side) replaces the old one.
        with open(tri, "w") as f:
            f.write("".join(f"v {-far[0] + x} {far[1] + y} {far[2]}\n" for x, y in ((-1, -1), (1, -1), (0, 1))) + "f 1 2 3\n")
        n_err = len(viewer.lines("err"))
        xdo("key", "F5")
        viewer.wait_line("err", r"rtr-view: loaded .*tri\.obj", start=n_err)
        viewer.wait_line("err", r"move speed", start=n_err)
        time.sleep(0.5)
        xdo("key", "f")
        time.sleep(0.5)
        (cr, _, _) = pose()
        check(cr[0] < -900, f"F5 reloads the edited file (the camera frames it at x {cr[0]:.0f})")
        # Right: the next file of the command line.
        n_err = len(viewer.lines("err"))
        xdo("key", "Right")
        viewer.wait_line("err", r"rtr-view: loaded .*second\.obj", start=n_err)
        check(True, "Right loads the next file of the command line")

        # The environment's controls (--env sky): the rotation slider prefilters the environment again when let go
        # and turns what the view shows; the background blur changes the backdrop without prefiltering again.
        def drag_slider(widget, fraction):
            x0, y0, x1, y1 = latest_rect(widget)
            xdo("mousemove", "--window", win, (x0 + x1) // 2, (y0 + y1) // 2)
            time.sleep(0.3)
            xdo("mousedown", "1")
            time.sleep(0.3)
            for i in range(1, 6):
                xdo("mousemove", "--window", win, (x0 + x1) // 2 + int(i * fraction * (x1 - x0) / 5), (y0 + y1) // 2)
                time.sleep(0.15)
            xdo("mouseup", "1")

        xdo("key", "1")
        xdo("key", "F1")
        wait_title("| shaded |")
        panel_now = latest_rect("panel")
        xdo("mousemove", "--window", win, (panel_now[0] + panel_now[2]) // 2, SIZE[1] // 2)
        for _ in range(30):  # one notch at a time, until the section's header is near the top
            if latest_rect("environment")[1] < 120:
                break
            xdo("click", "5")
            time.sleep(0.4)
        click("environment")
        check(latest_rect("env-blur")[3] <= SIZE[1], f"the environment section opens in view ({latest_rect('env-blur')})")
        right = latest_rect("panel")[2] + 20
        settle()
        unturned = screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1])
        n_err = len(viewer.lines("err"))
        drag_slider("env-rotation", 0.4)
        viewer.wait_line("err", r"rtr-view: environment sky prefiltered", start=n_err)
        settle(2.0)
        turned = screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1])
        check(turned != unturned, "the rotation slider, let go, prefilters the environment again and turns the view")
        n_err = len(viewer.lines("err"))
        drag_slider("env-blur", 0.4)
        settle(2.0)
        check(screen_pixels(fbdir, right, 0, SIZE[0], SIZE[1]) != turned, "the blur slider blurs the backdrop")
        check(not any("prefiltered" in line for line in viewer.lines("err")[n_err:]),
              "the blur needs no new prefiltering")
    except Fail as e:
        print("FAIL:", e, flush=True)
        return finish(viewer, xvfb, ok=False, t0=t0, xdo=None)
    rc = finish(viewer, xvfb, ok=True, t0=t0, xdo=xdo)
    ini = os.path.join(config, "rtr", "imgui.ini")
    if rc == 0 and not os.path.exists(ini):
        print(f"FAIL: the panel's layout was not saved to {ini}", flush=True)
        return 1
    print(f"ok: the panel's layout is saved to $XDG_CONFIG_HOME/rtr/imgui.ini", flush=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
