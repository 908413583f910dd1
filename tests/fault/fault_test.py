#!/usr/bin/env python3
"""Fault injection against the real executables (issue 33), each run under a timeout:

- a FIFO as scene, --mtl, mtllib and .spv: a prompt error naming it (it used to block forever in open);
- /dev/zero as mtllib, --mtl and .spv: an error naming it, memory bounded (it used to read gigabytes);
- disk full during `rtr-bake --force`: exit 1 naming the output, the older scene and textures intact, no
  temporary left. On a 2 MiB tmpfs where mounting is possible (root); elsewhere a file size limit
  (RLIMIT_FSIZE), which the kernel enforces on every write just as a full disk (EFBIG for ENOSPC);
- a memory limit (RLIMIT_AS in the child): out of memory is an error naming the file and the stage, exit 1,
  no signal, nothing written;
- rtr-reflect's worker dies with its parent and is bounded in memory.

usage: fault_test.py BIN_DIR SOURCE_DIR
"""
import os
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zlib
import struct

BIN, SRC = sys.argv[1], sys.argv[2]
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def run(args, timeout=60, limit_as=None, limit_fsize=None):
    def pre():
        if limit_as:
            resource.setrlimit(resource.RLIMIT_AS, (limit_as, limit_as))
        if limit_fsize:
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_fsize, resource.RLIM_INFINITY))
    t0 = time.monotonic()
    try:
        p = subprocess.run([os.path.join(BIN, args[0])] + args[1:], capture_output=True, text=True,
                           errors="replace", timeout=timeout, preexec_fn=pre)
        return p.returncode, p.stderr, time.monotonic() - t0
    except subprocess.TimeoutExpired:
        return "timeout", "", time.monotonic() - t0


def expect_error(args, names, what, timeout=30, **kw):
    rc, err, secs = run(args, timeout=timeout, **kw)
    check(rc == 1 and names in err, f"{what}: exit {rc} in {secs:.1f} s, names '{names}'"
          + ("" if rc == 1 and names in err else f"\n     stderr: {err.strip()[-400:]}"))
    return err


def grid_obj(path, n, mtl=None):
    with open(path, "w") as f:
        if mtl:
            f.write(f"mtllib {mtl}\nusemtl a\n")
        for y in range(n + 1):
            for x in range(n + 1):
                f.write(f"v {x} {y} {(x * y) % 7 * 0.1}\nvt {x / n} {y / n}\n")
        for y in range(n):
            for x in range(n):
                a = y * (n + 1) + x + 1
                b, c = a + 1, a + n + 1
                f.write(f"f {a}/{a} {b}/{b} {c + 1}/{c + 1} {c}/{c}\n")


def png(path, w, h, grey):
    """An 8-bit grey PNG of one value: a few KB however large it says it is."""
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xFFFFFFFF)
    z = zlib.compressobj(9)
    row = b"\0" + bytes([grey]) * w
    data = b"".join(z.compress(row) for _ in range(h)) + z.flush()
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
                + chunk(b"IDAT", data) + chunk(b"IEND", b""))


def files_under(d):
    return sorted(os.path.relpath(os.path.join(r, f), d) for r, _, fs in os.walk(d) for f in fs)


def read(p):
    with open(p, "rb") as f:
        return f.read()


tmp = tempfile.mkdtemp(prefix="rtr_fault_")
try:
    cornell = os.path.join(SRC, "assets-src/rt/cornell_box.obj")
    fifo = os.path.join(tmp, "pipe.obj")
    os.mkfifo(fifo)
    spv_fifo = os.path.join(tmp, "pipe.spv")
    os.mkfifo(spv_fifo)
    zero_spv = os.path.join(tmp, "zero.spv")
    os.symlink("/dev/zero", zero_spv)
    zero_lib = os.path.join(tmp, "zerolib.obj")
    with open(zero_lib, "w") as f:
        f.write("mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    fifo_lib = os.path.join(tmp, "fifolib.obj")
    with open(fifo_lib, "w") as f:
        f.write("mtllib pipe.obj\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    out = os.path.join(tmp, "o.png")

    print("-- FIFOs and devices")
    expect_error(["rtr-trace", fifo, "-o", out, "--size", "8x8", "-q"], "pipe.obj: a FIFO", "rtr-trace FIFO scene")
    expect_error(["rtr-bake", fifo, os.path.join(tmp, "f.rtrscene")], "pipe.obj: a FIFO", "rtr-bake FIFO scene")
    expect_error(["rtr-trace", cornell, "--mtl", fifo, "-o", out, "--size", "8x8", "-q"], "pipe.obj: a FIFO",
                 "rtr-trace --mtl FIFO")
    expect_error(["rtr-trace", fifo_lib, "-o", out, "--size", "8x8", "-q"], "pipe.obj: a FIFO", "rtr-trace mtllib FIFO")
    expect_error(["rtr-reflect", spv_fifo], "pipe.spv: a FIFO", "rtr-reflect FIFO .spv")
    expect_error(["rtr-view", fifo, "--headless", "--screenshot", out], "pipe.obj: a FIFO", "rtr-view FIFO scene",
                 timeout=60)
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    expect_error(["rtr-trace", zero_lib, "-o", out, "--size", "8x8", "-q"], "/dev/zero: a character device",
                 "rtr-trace mtllib /dev/zero")
    expect_error(["rtr-bake", cornell, os.path.join(tmp, "z.rtrscene"), "--mtl", "/dev/zero"],
                 "/dev/zero: a character device", "rtr-bake --mtl /dev/zero")
    expect_error(["rtr-reflect", zero_spv], "zero.spv: a character device", "rtr-reflect /dev/zero as .spv")
    expect_error(["rtr-trace", "/dev/zero", "-o", out], "/dev/zero", "rtr-trace /dev/zero as scene")
    rss = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    check(rss < 512 * 1024, f"largest child's peak memory {rss // 1024} MB (bounded; it was 7.8-14 GB)")
    check(not os.path.exists(out), "no image written by any failed run")

    print("-- disk full during rtr-bake --force")
    disk = os.path.join(tmp, "disk")
    os.makedirs(disk)
    mounted = os.geteuid() == 0 and subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", disk], capture_output=True).returncode == 0
    try:
        print("     " + ("a 2 MiB tmpfs" if mounted else "no mount possible here: RLIMIT_FSIZE of 2 MiB stands in"))
        src = os.path.join(tmp, "src")
        os.makedirs(src)
        with open(os.path.join(src, "g.mtl"), "w") as f:
            f.write("newmtl a\nmap_Kd t.png\n")
        png(os.path.join(src, "t.png"), 16, 16, 40)
        grid_obj(os.path.join(src, "g.obj"), 8, "g.mtl")
        scene = os.path.join(disk, "g.rtrscene")
        rc, err, _ = run(["rtr-bake", os.path.join(src, "g.obj"), scene])
        check(rc == 0, f"first bake fits (exit {rc}) {err.strip()[-200:]}")
        old_files = files_under(disk)
        old = {f: read(os.path.join(disk, f)) for f in old_files}
        png(os.path.join(src, "t.png"), 16, 16, 200)  # a new texture, and a scene too large for the disk
        grid_obj(os.path.join(src, "g.obj"), 300, "g.mtl")
        limit = {} if mounted else {"limit_fsize": 2 << 20}
        err = expect_error(["rtr-bake", os.path.join(src, "g.obj"), scene, "--force"], "g.rtrscene",
                           "bake --force on a full disk", **limit)
        check("No space left" in err or "File too large" in err, "the message says why: " + err.strip()[-120:])
        check(files_under(disk) == old_files, "no file added or left behind (no temporary)")
        check(all(read(os.path.join(disk, f)) == old[f] for f in old_files),
              "the older scene and its textures are byte for byte intact")
    finally:
        if mounted:
            subprocess.run(["umount", disk])

    print("-- out of memory (RLIMIT_AS in the child)")
    big = os.path.join(tmp, "big")
    os.makedirs(big)
    png(os.path.join(big, "huge.png"), 16384, 16384, 128)  # 1 GiB of RGBA once decoded
    with open(os.path.join(big, "b.mtl"), "w") as f:
        f.write("newmtl a\nmap_Kd huge.png\n")
    grid_obj(os.path.join(big, "b.obj"), 4, "b.mtl")
    baked = os.path.join(big, "out", "b.rtrscene")
    err = expect_error(["rtr-bake", os.path.join(big, "b.obj"), baked], "huge.png: out of memory",
                       "rtr-bake: a texture decode out of memory (was std::terminate)", limit_as=768 << 20, timeout=120)
    check(not os.path.exists(os.path.join(big, "out")), "nothing written by the failed bake")
    temple = os.path.join(SRC, "assets-src/temple/temple.obj.zst")
    expect_error(["rtr-trace", temple, "-o", out, "--size", "16384x16384", "-q", "--threads", "2"],
                 "out of memory while tracing " + temple, "rtr-trace: a 16384² image under 600 MB", limit_as=600 << 20, timeout=120)
    err = expect_error(["rtr-view", cornell, "--headless", "--size", "16384x16384", "--screenshot", out],
                       "out of memory before uploading", "rtr-view: a 16384² frame under 2 GB (was a crash)",
                       limit_as=2 << 30, timeout=120)
    check("would fit" in err, "rtr-view says what would fit")
    expect_error(["rtr-view", temple, "--headless", "--size", "64x64", "--screenshot", out], "out of memory",
                 "rtr-view under 600 MB (llvmpipe crashed in vkCreateDevice)", limit_as=600 << 20, timeout=120)
    check(not os.path.exists(out), "no image written by the failed runs")

    print("-- rtr-reflect's worker")
    bomb = os.path.join(tmp, "bomb.comp")
    with open(bomb, "w") as f:  # x + x + ... (2^40 terms): runs until stopped
        f.write("#version 450\nlayout(local_size_x = 1) in;\n#define A0 x +\n")
        for i in range(1, 41):
            f.write(f"#define A{i} A{i - 1} A{i - 1}\n")
        f.write("void main() { int x = 0; int y = A40 x; }\n")
    p = subprocess.Popen([os.path.join(BIN, "rtr-reflect"), bomb], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    child = None
    for _ in range(100):
        try:
            with open(f"/proc/{p.pid}/task/{p.pid}/children") as f:
                kids = f.read().split()
            if kids:
                child = int(kids[0])
                break
        except OSError:
            pass
        time.sleep(0.05)
    check(child is not None, "rtr-reflect works in a child process")
    if child:
        time.sleep(0.5)
        p.send_signal(signal.SIGTERM)
        p.wait(timeout=10)
        gone = False
        for _ in range(100):
            try:
                with open(f"/proc/{child}/stat") as f:
                    gone = f.read().split()[2] == "Z"
            except OSError:
                gone = True
            if gone:
                break
            time.sleep(0.05)
        check(gone, "the worker dies with its parent (SIGTERM to rtr-reflect)")
    # Its own limit is 2 GB (33 s of this on the development VM); a lower one inherited is kept.
    rc, err, secs = run(["rtr-reflect", bomb], timeout=120, limit_as=700 << 20)
    check(rc == 1 and "bomb.comp" in err, f"left alone, the worker stops at its memory limit: exit {rc} in {secs:.0f} s, "
          f"names the file ({err.strip()[-160:]})")
finally:
    shutil.rmtree(tmp, ignore_errors=True)

print(f"{len(failures)} failures")
sys.exit(1 if failures else 0)
