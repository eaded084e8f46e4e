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
  signal     WHITTED  SIGTERM, then SIGINT, to mpirun mid-render: non-zero exit, previous output
             intact, no temporary file, and every rank gone: within 1.5 s with Open MPI's defaults
             (mpirun sends the ranks SIGCONT, waits odls_base_sigkill_timeout = 1 s, then SIGTERM,
             which they obey at once, rank 0 saying so), and within 1 s with
             --mca odls_base_sigkill_timeout 0 (SIGTERM at once, SIGKILL right after).
  sweep      WHITTED SOURCE_DIR  scripts/validate on five scenes of tests/pov and one broken scene,
             serially and as mpirun -np 3 scripts/validate --mpi: the same verdict lines, the same
             index rows, the same per-scene output (label pov too: it runs POV-Ray).
  startup    WHITTED  the program does not link libmpi and does not load it without MPI in the
             environment; under mpirun it loads it (LD_DEBUG=files).

mpirun missing is a failure with the package to install, never a skip."""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

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


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


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


def read_exr(path):
    import numpy
    import OpenImageIO as oiio
    image = oiio.ImageInput.open(path)
    if image is None:
        fail(f"cannot read {path}: {oiio.geterror()}")
    pixels = image.read_image(format="float")
    image.close()
    return numpy.asarray(pixels)


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
        run = subprocess.run([whitted, "render", scene, "-o", reference, "-q"], env=env, capture_output=True,
                             text=True)
        if run.returncode != 0:
            fail(f"one-process render of {name}: exit {run.returncode}: {run.stderr}")
        expected = read_exr(reference)
        for ranks, threads, btl in [(1, 2, None), (2, 1, None), (3, 1, None), (4, 1, None), (2, 1, "self,tcp")]:
            label = f"{name}, {ranks} rank(s)" + (f", btl {btl}" if btl else "")
            output = os.path.join(directory, f"{name}-{ranks}-{btl or 'default'}.exr")
            command = mpirun_prefix(ranks, btl) + [whitted, "render", scene, "-o", output, "-t", str(threads)]
            started = time.monotonic()
            run = subprocess.run(command, env=mpi_env(), capture_output=True, text=True, timeout=300)
            seconds = time.monotonic() - started
            if run.returncode != 0:
                problems.append(f"{label}: exit {run.returncode}: {run.stderr.strip()[-2000:]}")
                continue
            if f"rendered by {ranks} MPI rank(s)" not in run.stderr:
                problems.append(f"{label}: the render did not say it ran on {ranks} ranks: {run.stderr.strip()}")
                continue
            got = read_exr(output)
            if got.shape != expected.shape:
                problems.append(f"{label}: shape {got.shape}, expected {expected.shape}")
                continue
            differing = int(numpy.count_nonzero(numpy.any(got != expected, axis=-1)))
            if differing:
                problems.append(f"{label}: {differing} pixel(s) differ from the one-process render")
            print(f"{label}: {seconds:.2f}s, {'identical' if not differing else 'DIFFERENT'} "
                  f"({w}x{h}, {s}x{s} samples, {threads} thread(s) per rank)")
    if problems:
        fail("\n  ".join(problems))
    print("PASS: every distributed render equals the one-process render float for float")


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
    no_grace = ("--mca", "odls_base_sigkill_timeout", "0")
    said = 0  # default-grace runs in which rank 0's message came through
    for sig, mca, limit in ((signal.SIGTERM, (), 1.5), (signal.SIGINT, (), 1.5), (signal.SIGTERM, no_grace, 1.0),
                            (signal.SIGINT, no_grace, 1.0)):
        process, pids, output, scene = start_big_render(whitted, directory, 2, mca)
        process.send_signal(sig)
        sent = time.monotonic()
        deadline = sent + 10
        while time.monotonic() < deadline and (process.poll() is None or any(alive(p) for p in pids.values())):
            time.sleep(0.01)
        seconds = time.monotonic() - sent
        text = process.communicate(timeout=10)[0] if process.poll() is not None else ""
        name = signal.Signals(sig).name + (" " + " ".join(mca) if mca else "")
        print(f"{name} to mpirun: mpirun exit {process.returncode}, every rank gone after {seconds:.2f}s; "
              f"output:\n{text}")
        if seconds > limit:
            problems.append(f"{name}: the ranks took {seconds:.2f}s to end (more than {limit} s)")
        if not mca and "interrupted; nothing written" in text:
            said += 1
        if process.returncode == 0:
            problems.append(f"{name}: mpirun exited 0")
        check_outcome(directory, output, scene, pids, problems, name)
        os.remove(output)
    # mpirun, shutting down, can drop a rank's last line of output, so one of the two runs must
    # show that rank 0 stopped on the signal itself (not killed), not necessarily both.
    if said == 0:
        problems.append("in neither default run did rank 0 say it stopped without writing")
    if problems:
        fail("\n  ".join(problems))
    print("PASS: SIGTERM and SIGINT to mpirun end every rank (within 1 s with odls_base_sigkill_timeout 0, "
          "1.5 s with mpirun's 1 s default grace), the previous output intact")


def startup(whitted, directory):
    problems = []
    ldd = subprocess.run(["ldd", whitted], capture_output=True, text=True)
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
        run = subprocess.run(command, env=env, capture_output=True, text=True)
        if run.returncode != 0:
            problems.append(f"{' '.join(command)}: exit {run.returncode}")
        if "libmpi" in run.stderr or "libwhitted_mpi" in run.stderr:
            problems.append(f"{' '.join(command)} loaded MPI without being started by mpirun")
    env = mpi_env()
    env["LD_DEBUG"] = "files"
    run = subprocess.run(mpirun_prefix(1) + [whitted, "render", scene, "-o", output, "-q"], env=env,
                         capture_output=True, text=True, timeout=120)
    if run.returncode != 0:
        problems.append(f"mpirun -np 1 whitted render: exit {run.returncode}: {run.stderr[-2000:]}")
    if "libwhitted_mpi.so" not in run.stderr or "libmpi.so" not in run.stderr:
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
        run = subprocess.run(command + ["--out", out] + scenes, env=env, capture_output=True, text=True, timeout=600)
        seconds = time.monotonic() - started
        print(f"{label} ({seconds:.1f}s, exit {run.returncode}):\n{run.stdout}{run.stderr[-3000:]}")
        verdicts = [line for line in run.stdout.splitlines() if re.match(r"\[\d+/\d+\] ", line)]
        with open(os.path.join(out, "index.html")) as f:
            rows = [line for line in f if line.startswith("<tr class=")]
        texts = {}
        for name in ("ambient_only", "box", "facing_mirrors_depth12", "blinn_p100", "directional_light", "broken"):
            with open(os.path.join(out, name + ".txt")) as f:
                # The check's output names the report directory, which differs between the runs.
                texts[name] = f.read().replace(out, "OUT")
        runs[label] = (run.returncode, verdicts, rows, texts, run.stderr)
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


def main():
    modes = {"identical": identical, "kill": kill, "signal": signal_mode, "startup": startup, "sweep": sweep}
    if len(sys.argv) < 3 or sys.argv[1] not in modes:
        print(__doc__)
        sys.exit(2)
    mode, whitted = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory(prefix=f"whitted-mpi-{mode}-") as directory:
        modes[mode](whitted, directory, *sys.argv[3:])


if __name__ == "__main__":
    main()
