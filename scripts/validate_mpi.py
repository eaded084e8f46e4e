#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The queue of `mpirun -np N scripts/validate --mpi`: run by scripts/validate on every rank.
Rank 0 hands out scenes one at a time (a check takes seconds, so one at a time costs nothing and
balances best); every rank, rank 0 included, runs `whitted check` on the scenes it is given and
sends rank 0 the exit status and the whole output. Rank 0 writes each output to OUT/NAME.txt,
as the serial run does, and prints one line per scene, in the order given: INDEX<TAB>STATUS.
scripts/validate then reads the verdicts from those files exactly as in a serial run.

  validate_mpi.py --out DIR --whitted PROGRAM [--check-arg ARG]... -- NAME SCENE [NAME SCENE]...

Reports (OUT/NAME/) are written by the rank that checked the scene, on its host: on a cluster
put OUT on a shared filesystem for the index page's links to work (docs/distributed.md)."""

import argparse
import os
import subprocess
import sys
import tempfile
import time

try:
    from mpi4py import MPI
except ImportError:
    print("validate: --mpi needs mpi4py: apt-get install python3-mpi4py", file=sys.stderr)
    sys.exit(2)

TAG_RESULT, TAG_ITEM = 1, 2


def start_check(args, name, scene):
    """`whitted check` of one scene, its output into an unnamed file (a pipe could fill while
    rank 0 serves the queue)."""
    env = dict(os.environ)
    env["WHITTED_MPI"] = "0"  # `whitted check` is one process; the ranks are this script's
    log = tempfile.TemporaryFile()
    process = subprocess.Popen([args.whitted, "check", scene, "--report", os.path.join(args.out, name)] +
                               args.check_arg, stdout=log, stderr=subprocess.STDOUT, env=env)
    return process, log


def finish_check(check):
    process, log = check
    process.wait()
    log.seek(0)
    output = log.read()
    log.close()
    return process.returncode, output


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--out", required=True)
    parser.add_argument("--whitted", required=True)
    parser.add_argument("--check-arg", action="append", default=[])
    parser.add_argument("pairs", nargs="+")
    args = parser.parse_args()
    if len(args.pairs) % 2:
        parser.error("NAME SCENE pairs expected")
    items = list(zip(args.pairs[0::2], args.pairs[1::2]))
    os.makedirs(args.out, exist_ok=True)
    comm = MPI.COMM_WORLD
    rank, size = comm.Get_rank(), comm.Get_size()

    if rank != 0:
        message = None
        while True:
            comm.send(message, dest=0, tag=TAG_RESULT)  # the last result (none at first): ask for more
            index = comm.recv(source=0, tag=TAG_ITEM)
            if index is None:
                return 0
            code, output = finish_check(start_check(args, *items[index]))
            message = (index, code, output)

    # Rank 0: the queue, and checks of its own while it waits for the others.
    statuses = {}
    outputs = {}
    next_index = 0
    told_done = 0
    mine = None  # (index, (Popen, log))
    checked_by = {}  # rank: scenes it checked
    while len(statuses) < len(items) or told_done < size - 1 or mine:
        busy = False
        if mine is None and next_index < len(items):
            mine = (next_index, start_check(args, *items[next_index]))
            next_index += 1
        if mine and mine[1][0].poll() is not None:
            index, check = mine
            statuses[index], outputs[index] = finish_check(check)
            checked_by[0] = checked_by.get(0, 0) + 1
            mine = None
            busy = True
        status = MPI.Status()
        if comm.Iprobe(source=MPI.ANY_SOURCE, tag=TAG_RESULT, status=status):
            message = comm.recv(source=status.Get_source(), tag=TAG_RESULT)
            if message is not None:
                index, code, output = message
                statuses[index], outputs[index] = code, output
                checked_by[status.Get_source()] = checked_by.get(status.Get_source(), 0) + 1
            if next_index < len(items):
                comm.send(next_index, dest=status.Get_source(), tag=TAG_ITEM)
                next_index += 1
            else:
                comm.send(None, dest=status.Get_source(), tag=TAG_ITEM)
                told_done += 1
            busy = True
        if not busy:
            time.sleep(0.02)
    print(f"validate: {len(items)} scene(s) checked by {size} MPI rank(s): " +
          ", ".join(f"rank {r} {checked_by.get(r, 0)}" for r in range(size)), file=sys.stderr)
    for index, (name, _) in enumerate(items):
        with open(os.path.join(args.out, name + ".txt"), "wb") as f:
            f.write(outputs[index])
        print(f"{index}\t{statuses[index]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
