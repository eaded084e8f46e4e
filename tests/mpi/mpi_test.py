#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Distributed rendering under mpirun (docs/distributed.md). Each mode is one ctest (label mpi):

  identical  WHITTED SCENE_DIR  two scenes (one ray per pixel at 517x389, 2x2 samples at 301x203,
             mirrors, sizes not multiples of the 32-pixel tile) rendered by one process without
             MPI and by mpirun -np 1, 2, 3, 4: every float of the EXR equal (tolerance 0), read
             back with OpenImageIO, not with Whitted. Also -np 2 over the TCP transport only
             (--mca btl self,tcp): nothing relies on shared memory between the ranks.
  kill       WHITTED  kill -9 one rank (not rank 0) mid-render of a large image: mpirun exits
             non-zero and says a rank died, the previous output is byte for byte intact, no
             temporary file is left, no rank is left running.
  signal     WHITTED  SIGTERM and SIGINT to mpirun mid-render, five runs with Open MPI's defaults:
             non-zero exit, previous output intact, no temporary file, every rank gone, the median
             time from the signal to the last rank gone under 1 s (mpirun sends the ranks SIGCONT at
             once and SIGTERM only a second later; a rank that was not stopped takes that SIGCONT
             as the end of the job), no run over 2 s. Then job control: SIGTSTP to mpirun stops
             every rank, SIGCONT resumes them, and the render finishes with the one-process pixels.
  sweep      WHITTED SOURCE_DIR  scripts/validate on five scenes of tests/pov and one broken scene,
             serially and as mpirun -np 3 scripts/validate --mpi: the same verdict lines, the same
             index rows, the same per-scene output (label pov too: it runs POV-Ray).
  startup    WHITTED  the program does not link libmpi and does not load it without MPI in the
             environment; under mpirun it loads it (LD_DEBUG=files).

  hosts      WHITTED  two simulated hosts: network namespaces joined by a veth pair (10.77.0.1 and
             .2), mpirun in the first, netns_agent.sh (ip netns exec) as its launcher instead of
             ssh, Open MPI's TCP transport only (btl tcp,self, no shared memory): each rank in
             its namespace (ip netns identify through the same launch), 2 hosts x 1 and x 2 ranks,
             the one-process pixels. SKIPPED (exit 77) without ip or CAP_NET_ADMIN; the
             namespaces are deleted however it ends.

mpirun missing is a failure with the package to install, never a skip."""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
from harness import fail, read_pixels, run, skip  # noqa: E402  (tests/harness.py)

MIRRORS = """version: 1
camera: {{ eye: [0, 3, 9], look_at: [0, 0.5, 0], fov: 55 }}
image: {{ width: {w}, height: {h}, samples: {s}, background: [0.1, 0.1, 0.15] }}
render: {{ max_depth: 8 }}
lights:
  - {{ type: point, position: [-5, 8, 6], intensity: 0.6 }}
  - {{ type: point, position: [5, 6, 4], intensity: 0.4 }}
materials:
  mirror: {{ ka: 0.02, kd: 0.2, ks: 0.4, p: 60, km: 0.6 }}
  matte: {{ ka: 0.05, kd: [0.7, 0.3, 0.2] }}
objects:
  - {{ type: plane, point: [0, 0, 0], normal: [0, 1, 0], material: mirror }}
  - {{ type: box, min: [-3, 0, -5], max: [3, 2, -4.5], material: matte }}
""" + "".join(
    f"  - {{{{ type: sphere, center: [{x}, 0.6, {z}], radius: 0.55, material: mirror }}}}\n"
    for x in range(-4, 5, 2) for z in range(-4, 3, 2))

OLD_BYTES = b"the previous render: must survive a distributed render that fails\n" * 100


def mpirun_prefix(ranks, btl=None):
    mpirun = shutil.which("mpirun")
    if not mpirun:
        fail("mpirun not found: apt-get install openmpi-bin libopenmpi-dev (scripts/setup --with-test-tools does)")
    command = [mpirun, "--oversubscribe", "-np", str(ranks)]
    if btl:
        command += ["--mca", "btl", btl]
    return command


def mpi_env():
    env = dict(os.environ)
    # Open MPI refuses root without both; the tests run as root in containers and chroots.
    env["OMPI_ALLOW_RUN_AS_ROOT"] = "1"
    env["OMPI_ALLOW_RUN_AS_ROOT_CONFIRM"] = "1"
    env.pop("WHITTED_MPI", None)
    return env


def identical(whitted, directory):
    import numpy
    problems = []
    for name, (w, h, s) in {"single": (517, 389, 1), "samples": (301, 203, 2)}.items():
        scene = os.path.join(directory, f"{name}.yaml")
        with open(scene, "w") as f:
            f.write(MIRRORS.format(w=w, h=h, s=s))
        reference = os.path.join(directory, f"{name}-one-process.exr")
        env = mpi_env()
        env["WHITTED_MPI"] = "0"
        run([whitted, "render", scene, "-o", reference, "-q"], env=env)
        expected = read_pixels(reference)
        for ranks, threads, btl in [(1, 2, None), (2, 1, None), (3, 1, None), (4, 1, None), (2, 1, "self,tcp")]:
            label = f"{name}, {ranks} rank(s)" + (f", btl {btl}" if btl else "")
            output = os.path.join(directory, f"{name}-{ranks}-{btl or 'default'}.exr")
            command = mpirun_prefix(ranks, btl) + [whitted, "render", scene, "-o", output, "-t", str(threads)]
            started = time.monotonic()
            result = run(command, env=mpi_env(), expect=None, timeout=300)
            seconds = time.monotonic() - started
            if result.returncode != 0:
                problems.append(f"{label}: exit {result.returncode}: {result.stderr.strip()[-2000:]}")
                continue
            if f"rendered by {ranks} MPI rank(s)" not in result.stderr:
                problems.append(f"{label}: the render did not say it ran on {ranks} ranks: {result.stderr.strip()}")
                continue
            got = read_pixels(output)
            if got.shape != expected.shape:
                problems.append(f"{label}: shape {got.shape}, expected {expected.shape}")
                continue
            differing = int(numpy.count_nonzero(numpy.any(got != expected, axis=-1)))
            if differing:
                problems.append(f"{label}: {differing} pixel(s) differ from the one-process render")
            print(f"{label}: {seconds:.2f}s, {'identical' if not differing else 'DIFFERENT'} "
                  f"({w}x{h}, {s}x{s} samples, {threads} thread(s) per rank)")
        # A crop window shared among 3 ranks: the one-process render's pixels in that window. The
        # window starts and ends inside tiles, so partial tiles are cut on rank 0.
        x, y, cw, ch = 45, 70, 200, 101
        output = os.path.join(directory, f"{name}-crop.exr")
        command = mpirun_prefix(3) + [whitted, "render", scene, "-o", output, "-t", "1", "--crop", f"{x},{y},{cw},{ch}"]
        result = run(command, env=mpi_env(), expect=None, timeout=300)
        if result.returncode != 0:
            problems.append(f"{name}, --crop on 3 ranks: exit {result.returncode}: {result.stderr.strip()[-2000:]}")
            continue
        got, window = read_pixels(output), expected[y:y + ch, x:x + cw]
        if got.shape != window.shape or not numpy.array_equal(got, window):
            problems.append(f"{name}, --crop on 3 ranks: not the one-process render's window ({got.shape})")
        print(f"{name}, --crop {x},{y},{cw},{ch} on 3 ranks: {'identical' if not problems else 'see above'}")
    if problems:
        fail("\n  ".join(problems))
    print("PASS: every distributed render (whole, and a crop window) equals the one-process render float for float")


def big_scene(directory):
    scene = os.path.join(directory, "big.yaml")
    with open(scene, "w") as f:
        f.write(MIRRORS.format(w=2400, h=1800, s=4))
    return scene


def rank_pids(marker):
    """{rank: pid} of the whitted processes whose command line holds `marker` (our output path)."""
    pids = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/cmdline", "rb") as f:
                cmdline = f.read().split(b"\0")
            if not cmdline or not cmdline[0].endswith(b"whitted") or marker.encode() not in cmdline:
                continue
            with open(f"/proc/{entry}/environ", "rb") as f:
                environ = dict(v.split(b"=", 1) for v in f.read().split(b"\0") if b"=" in v)
            rank = environ.get(b"OMPI_COMM_WORLD_RANK")
            if rank is not None:
                pids[int(rank)] = int(entry)
        except (OSError, ValueError):
            continue
    return pids


def alive(pid):
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


def start_big_render(whitted, directory, ranks, mca=()):
    output = os.path.join(directory, "out.exr")
    with open(output, "wb") as f:
        f.write(OLD_BYTES)
    scene = big_scene(directory)
    process = subprocess.Popen(mpirun_prefix(ranks) + list(mca) + [whitted, "render", scene, "-o", output, "-t", "1", "-q"],
                               env=mpi_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    # Wait until every rank runs (and has had a moment to load the scene and start rendering).
    deadline = time.monotonic() + 30
    pids = {}
    while time.monotonic() < deadline and process.poll() is None:
        pids = rank_pids(output)
        if len(pids) == ranks:
            break
        time.sleep(0.05)
    if len(pids) != ranks:
        process.kill()
        fail(f"saw {len(pids)} of {ranks} ranks start: {process.communicate()[0]}")
    time.sleep(2.0)
    if process.poll() is not None:
        fail(f"the render ended before it could be interrupted (exit {process.returncode}): scene too small")
    return process, pids, output, scene


def check_outcome(directory, output, scene, pids, problems, what):
    with open(output, "rb") as f:
        if f.read() != OLD_BYTES:
            problems.append(f"{what}: the previous output was changed")
    left = sorted(set(os.listdir(directory)) - {os.path.basename(output), os.path.basename(scene)})
    if left:
        problems.append(f"{what}: files left behind: {left}")
    running = [pid for pid in pids.values() if alive(pid)]
    if running:
        problems.append(f"{what}: ranks still running: {running}")


def kill(whitted, directory):
    problems = []
    process, pids, output, scene = start_big_render(whitted, directory, 3)
    victim = pids[1]
    os.kill(victim, signal.SIGKILL)
    killed = time.monotonic()
    try:
        text, _ = process.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        process.kill()
        text = process.communicate()[0]
        problems.append("mpirun did not end within 30 s of a rank's death")
    seconds = time.monotonic() - killed
    gone = time.monotonic() + 2
    while time.monotonic() < gone and any(alive(p) for p in pids.values()):
        time.sleep(0.05)
    print(f"rank 1 (pid {victim}) killed; mpirun exit {process.returncode} after {seconds:.2f}s; its output:\n{text}")
    if process.returncode == 0:
        problems.append("mpirun exited 0 although a rank was killed")
    # Open MPI's own words for a rank that died ("exited on signal 9 (Killed)").
    if "signal 9" not in text and "Killed" not in text:
        problems.append("no message says that a rank was killed")
    check_outcome(directory, output, scene, pids, problems, "kill -9 rank 1")
    if problems:
        fail("\n  ".join(problems))
    print("PASS: a killed rank fails the job, clearly, with the previous output intact and nothing left behind")


def signal_mode(whitted, directory):
    problems = []
    said = 0  # runs in which rank 0's message came through
    times = []
    # Open MPI's defaults (no --mca): the ranks stop on mpirun's first SIGCONT, not its SIGTERM a
    # second later. Five runs, the median asserted: one run on a loaded 2-core VM can be late.
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGTERM, signal.SIGINT, signal.SIGTERM):
        process, pids, output, scene = start_big_render(whitted, directory, 2)
        process.send_signal(sig)
        sent = time.monotonic()
        deadline = sent + 10
        while time.monotonic() < deadline and (process.poll() is None or any(alive(p) for p in pids.values())):
            time.sleep(0.01)
        seconds = time.monotonic() - sent
        times.append(seconds)
        text = process.communicate(timeout=10)[0] if process.poll() is not None else ""
        name = signal.Signals(sig).name
        print(f"{name} to mpirun: mpirun exit {process.returncode}, every rank gone after {seconds:.2f}s; "
              f"output:\n{text}")
        if seconds > 2.0:
            problems.append(f"{name}: the ranks took {seconds:.2f}s to end (more than 2 s even for one run)")
        if "interrupted; nothing written" in text:
            said += 1
        if process.returncode == 0:
            problems.append(f"{name}: mpirun exited 0")
        check_outcome(directory, output, scene, pids, problems, name)
        os.remove(output)
    median = sorted(times)[len(times) // 2]
    print(f"signal to every rank gone: median {median:.2f}s of {', '.join(f'{t:.2f}' for t in times)}")
    if median >= 1.0:
        problems.append(f"median {median:.2f}s from the signal to every rank gone, not under 1 s")
    # mpirun, shutting down, can drop a rank's last line of output, so some runs must show that
    # rank 0 stopped on the signal itself (not killed), not necessarily all.
    if said == 0:
        problems.append("in no run did rank 0 say it stopped without writing")
    job_control(whitted, directory, problems)
    if problems:
        fail("\n  ".join(problems))
    print("PASS: SIGTERM and SIGINT to mpirun end every rank in under 1 s (median) with Open MPI's defaults, "
          "the previous output intact; a render stopped and resumed through mpirun finishes, identical")


def job_control(whitted, directory, problems):
    """Ctrl-Z / fg: mpirun forwards them to the ranks as SIGSTOP and SIGCONT, the same SIGCONT
    it sends when ending the job; a resumed render must finish, with the same pixels."""
    import numpy
    scene = os.path.join(directory, "resumed.yaml")
    with open(scene, "w") as f:
        f.write(MIRRORS.format(w=1600, h=1200, s=2))
    reference = os.path.join(directory, "resumed-one-process.exr")
    env = mpi_env()
    env["WHITTED_MPI"] = "0"
    run([whitted, "render", scene, "-o", reference, "-q"], env=env)
    output = os.path.join(directory, "resumed.exr")
    started = time.monotonic()
    process = subprocess.Popen(mpirun_prefix(2) + [whitted, "render", scene, "-o", output, "-t", "1", "-q"],
                               env=mpi_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    pids = {}
    while time.monotonic() < started + 30 and process.poll() is None and len(pids) < 2:
        pids = rank_pids(output)
        time.sleep(0.05)
    time.sleep(1.0)  # into the render (loading takes milliseconds)
    if process.poll() is not None or len(pids) < 2:
        problems.append(f"job control: the render ended before it could be stopped: {process.communicate()[0]}")
        return
    process.send_signal(signal.SIGTSTP)
    time.sleep(1.0)
    states = {}
    for rank, pid in pids.items():
        with open(f"/proc/{pid}/stat") as f:
            states[rank] = f.read().split(")")[-1].split()[0]
    process.send_signal(signal.SIGCONT)
    text = process.communicate(timeout=300)[0]
    print(f"job control: rank states while stopped {states}; after SIGCONT mpirun exit {process.returncode} "
          f"{time.monotonic() - started:.2f}s after the start; output:\n{text}")
    if any(state != "T" for state in states.values()):
        problems.append(f"job control: SIGTSTP to mpirun did not stop every rank: {states}")
    if process.returncode != 0:
        problems.append(f"job control: the resumed render failed (exit {process.returncode}): {text.strip()}")
        return
    got, expected = read_pixels(output), read_pixels(reference)
    if got.shape != expected.shape or numpy.any(got != expected):
        problems.append("job control: the resumed render differs from the one-process render")


def startup(whitted, directory):
    problems = []
    ldd = run(["ldd", whitted], expect=None)
    if "libmpi" in ldd.stdout:
        problems.append("whitted links libmpi:\n" + ldd.stdout)
    scene = os.path.join(directory, "small.yaml")
    with open(scene, "w") as f:
        f.write(MIRRORS.format(w=64, h=48, s=1))
    output = os.path.join(directory, "small.exr")
    env = dict(os.environ, LD_DEBUG="files")
    for key in list(env):
        if key.startswith(("OMPI_", "PMIX_", "PMI_", "SLURM_")) or key == "WHITTED_MPI":
            del env[key]
    for command in ([whitted, "--version"], [whitted, "render", scene, "-o", output, "-q"]):
        result = run(command, env=env, expect=None)
        if result.returncode != 0:
            problems.append(f"{' '.join(command)}: exit {result.returncode}")
        if "libmpi" in result.stderr or "libwhitted_mpi" in result.stderr:
            problems.append(f"{' '.join(command)} loaded MPI without being started by mpirun")
    env = mpi_env()
    env["LD_DEBUG"] = "files"
    result = run(mpirun_prefix(1) + [whitted, "render", scene, "-o", output, "-q"], env=env, expect=None,
                 timeout=120)
    if result.returncode != 0:
        problems.append(f"mpirun -np 1 whitted render: exit {result.returncode}: {result.stderr[-2000:]}")
    if "libwhitted_mpi.so" not in result.stderr or "libmpi.so" not in result.stderr:
        problems.append("under mpirun the MPI plug-in and libmpi were not loaded")
    if problems:
        fail("\n  ".join(problems))
    print("PASS: libmpi is not linked, not loaded without MPI, and loaded under mpirun")


def sweep(whitted, directory, source_dir):
    import re
    scenes = [os.path.join(source_dir, "tests", "pov", name + ".yaml")
              for name in ("ambient_only", "box", "facing_mirrors_depth12", "blinn_p100", "directional_light")]
    broken = os.path.join(directory, "broken.yaml")
    with open(broken, "w") as f:
        f.write("version: 1\ncamera: { eye: [0, 0, 5], look_at: [0, 0, 0], fov: 40 }\nimage: { width: [ }\n")
    scenes.append(broken)
    env = mpi_env()
    env["WHITTED_BUILD_DIR"] = os.path.dirname(os.path.dirname(os.path.abspath(whitted)))
    validate = os.path.join(source_dir, "scripts", "validate")
    runs = {}
    for label, command in (("serial", [validate]), ("mpi", mpirun_prefix(3) + [validate, "--mpi"])):
        out = os.path.join(directory, label)
        started = time.monotonic()
        result = run(command + ["--out", out] + scenes, env=env, expect=None, timeout=600)
        seconds = time.monotonic() - started
        print(f"{label} ({seconds:.1f}s, exit {result.returncode}):\n{result.stdout}{result.stderr[-3000:]}")
        verdicts = [line for line in result.stdout.splitlines() if re.match(r"\[\d+/\d+\] ", line)]
        with open(os.path.join(out, "index.html")) as f:
            rows = [line for line in f if line.startswith("<tr class=")]
        texts = {}
        for name in ("ambient_only", "box", "facing_mirrors_depth12", "blinn_p100", "directional_light", "broken"):
            with open(os.path.join(out, name + ".txt")) as f:
                # The check's output names the report directory, which differs between the runs.
                texts[name] = f.read().replace(out, "OUT")
        runs[label] = (result.returncode, verdicts, rows, texts, result.stderr)
    problems = []
    serial, mpi = runs["serial"], runs["mpi"]
    if len(serial[1]) != len(scenes):
        problems.append(f"the serial run printed {len(serial[1])} verdicts for {len(scenes)} scenes")
    if not any("ERROR broken" in line for line in serial[1]):
        problems.append("the broken scene was not an ERROR in the serial run")
    for what, index in (("exit status", 0), ("verdict lines", 1), ("index rows", 2)):
        if serial[index] != mpi[index]:
            problems.append(f"{what} differ:\n    serial: {serial[index]}\n    mpi:    {mpi[index]}")
    for name, text in serial[3].items():
        # Timings in the check's output differ from run to run; the verdict lines must not.
        strip = lambda t: [line for line in t.splitlines() if line.startswith(("PASS", "FAIL", "whitted: error"))]
        if strip(text) != strip(mpi[3][name]):
            problems.append(f"{name}: the check's verdict in NAME.txt differs")
    shares = re.search(r"checked by 3 MPI rank\(s\): rank 0 (\d+), rank 1 (\d+), rank 2 (\d+)", runs["mpi"][4])
    if not shares:
        problems.append("the MPI run did not say how the scenes were shared out among 3 ranks")
    elif sum(int(n) for n in shares.groups()) != len(scenes) or sum(int(n) > 0 for n in shares.groups()) < 2:
        problems.append(f"the scenes were not shared out: {shares.group(0)}")
    if problems:
        fail("\n  ".join(problems))
    print("PASS: the distributed sweep gives the serial run's verdicts and index rows")


def hosts(whitted, directory):
    """Two simulated hosts: network namespaces joined by a veth pair, Open MPI's TCP transport only,
    launched through netns_agent.sh instead of ssh. Skips (exit 77) without ip or CAP_NET_ADMIN."""
    import numpy
    ip = shutil.which("ip")
    if not ip:
        skip("no `ip` command (apt-get install iproute2; scripts/setup --with-test-tools does)")
    # The namespaces outlive this process: a SIGTERM (ctest's timeout, Ctrl-C) must reach `finally`.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    tag = str(os.getpid())
    ns = [f"whitted{tag}a", f"whitted{tag}b"]
    veth = [f"wv{tag}a", f"wv{tag}b"]
    addresses = ["10.77.0.1", "10.77.0.2"]

    def ip_run(*args, check=True):
        result = run([ip, *args], expect=None)
        if check and result.returncode != 0:
            raise RuntimeError(f"ip {' '.join(args)}: {result.stderr.strip()}")
        return result

    try:
        ip_run("netns", "add", ns[0])
    except RuntimeError as e:
        skip(f"cannot create a network namespace (needs CAP_NET_ADMIN): {e}")
    try:
        try:
            ip_run("netns", "add", ns[1])
            ip_run("link", "add", veth[0], "netns", ns[0], "type", "veth", "peer", "name", veth[1], "netns", ns[1])
            for n, v, a in zip(ns, veth, addresses):
                ip_run("-n", n, "addr", "add", a + "/24", "dev", v)
                ip_run("-n", n, "link", "set", v, "up")
                ip_run("-n", n, "link", "set", "lo", "up")
        except RuntimeError as e:
            # e.g. in a chroot whose / is no mount point, `ip -n` cannot make its mounts private
            # ("mount --make-rslave /" failed): this host cannot give the namespaces a network.
            skip(f"cannot set up the two namespaces' network here: {e}")
        agent = os.path.join(os.path.dirname(os.path.abspath(__file__)), "netns_agent.sh")
        env = mpi_env()
        env["WHITTED_NETNS_MAP"] = " ".join(f"{a}={n}" for a, n in zip(addresses, ns))
        problems = []
        scene = os.path.join(directory, "hosts.yaml")
        with open(scene, "w") as f:
            f.write(MIRRORS.format(w=517, h=389, s=2))
        reference = os.path.join(directory, "one-process.exr")
        one = dict(env, WHITTED_MPI="0")
        run([whitted, "render", scene, "-o", reference, "-q"], env=one)
        expected = read_pixels(reference)
        for per_host in (1, 2):
            ranks = 2 * per_host
            mpirun = [ip, "netns", "exec", ns[0], shutil.which("mpirun") or "mpirun", "--oversubscribe",
                      "-np", str(ranks), "--host", ",".join(f"{a}:{per_host}" for a in addresses),
                      "--map-by", "node", "--mca", "plm_rsh_agent", agent, "--mca", "btl", "tcp,self",
                      "--mca", "btl_tcp_if_include", "10.77.0.0/24", "--mca", "oob_tcp_if_include", "10.77.0.0/24"]
            # Where each rank runs: the same launch, `ip netns identify` in place of whitted.
            where = run(mpirun + [ip, "netns", "identify"], env=env, expect=None, timeout=120)
            names = sorted(where.stdout.split())
            print(f"{per_host} rank(s) per host: namespaces of the ranks {names} (exit {where.returncode})")
            if where.returncode != 0 or names != sorted(ns * per_host):
                problems.append(f"{per_host}/host: ranks not one set per namespace: {names}: {where.stderr[-1500:]}")
                continue
            output = os.path.join(directory, f"hosts-{per_host}.exr")
            started = time.monotonic()
            result = run(mpirun + [whitted, "render", scene, "-o", output, "-t", "1"], env=env, expect=None,
                         timeout=300)
            print(f"{per_host} rank(s) per host: exit {result.returncode} after {time.monotonic() - started:.2f}s: "
                  f"{result.stderr.strip()[-1500:]}")
            if result.returncode != 0 or f"rendered by {ranks} MPI rank(s)" not in result.stderr:
                problems.append(f"{per_host}/host: the render failed or did not run on {ranks} ranks")
                continue
            got = read_pixels(output)
            if got.shape != expected.shape or numpy.any(got != expected):
                problems.append(f"{per_host}/host: pixels differ from the one-process render")
        if problems:
            fail("\n  ".join(problems))
        print("PASS: two simulated hosts (network namespaces, TCP only) give the one-process pixels")
    finally:
        for n in ns:  # deleting a namespace deletes its end of the veth pair, and so the pair
            ip_run("netns", "del", n, check=False)


def main():
    modes = {"identical": identical, "kill": kill, "signal": signal_mode, "startup": startup, "sweep": sweep, "hosts": hosts}
    if len(sys.argv) < 3 or sys.argv[1] not in modes:
        print(__doc__)
        sys.exit(2)
    mode, whitted = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory(prefix=f"whitted-mpi-{mode}-") as directory:
        modes[mode](whitted, directory, *sys.argv[3:])


if __name__ == "__main__":
    main()
