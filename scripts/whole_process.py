#!/usr/bin/env python3
"""Times whole processes: runs each command N times, alternating between the commands, and
prints per command the median wall time, CPU (user + system), system time, page faults and
peak RSS, as the kernel reports them to wait4.

    python3 scripts/whole_process.py -n 15 -- CMD1 ARGS ... -- CMD2 ARGS ...

Alternating the commands run for run makes their figures comparable on a noisy host.
"""

import argparse
import os
import statistics
import sys
import time


def run_once(argv):
    start = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        try:
            os.execvp(argv[0], argv)
        finally:
            os._exit(127)
    _, status, usage = os.wait4(pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{' '.join(argv)} failed with status {status}")
    return {
        "wall ms": 1e3 * wall,
        "cpu ms": 1e3 * (usage.ru_utime + usage.ru_stime),
        "sys ms": 1e3 * usage.ru_stime,
        "faults": usage.ru_minflt + usage.ru_majflt,
        "peak RSS MiB": usage.ru_maxrss / 1024,
    }


def split_commands(rest):
    commands, current = [], []
    for word in rest:
        if word == "--":
            if current:
                commands.append(current)
            current = []
        else:
            current.append(word)
    if current:
        commands.append(current)
    return commands


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-n", type=int, default=15, help="runs of each command")
    parser.add_argument("rest", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    commands = split_commands(args.rest)
    if not commands:
        parser.error("no command given")
    runs = [[] for _ in commands]
    for _ in range(args.n):
        for k, argv in enumerate(commands):
            runs[k].append(run_once(argv))
    for argv, figures in zip(commands, runs):
        print(" ".join(argv))
        for key in figures[0]:
            values = [f[key] for f in figures]
            print(f"  {key:>13}: median {statistics.median(values):9.1f}"
                  f"  (min {min(values):.1f}, max {max(values):.1f})")


if __name__ == "__main__":
    main()
