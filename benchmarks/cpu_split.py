#!/usr/bin/python3
"""Runs a command and prints the CPU time (user + system, seconds, all threads) it spent
before and after the first line of its standard error that contains MARKER:
"BEFORE AFTER". The command's standard error goes to LOG. CPU time, unlike wall time,
hardly changes when other processes share the machine.
usage: cpu_split.py MARKER LOG COMMAND [ARGS...]"""
import os
import subprocess
import sys


def cpu_seconds_of(pid):
    # /proc/PID/stat fields 14 and 15: utime and stime of every thread, in clock ticks.
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    marker, log_path, command = sys.argv[1], sys.argv[2], sys.argv[3:]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    before = None
    with open(log_path, "w") as log:
        for line in process.stderr:
            log.write(line)
            if before is None and marker in line:
                before = cpu_seconds_of(process.pid)
    _, status, usage = os.wait4(process.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"cpu_split.py: {command[0]} exited {os.waitstatus_to_exitcode(status)}; "
                 f"see {log_path}")
    if before is None:
        sys.exit(f"cpu_split.py: no line of {log_path} contains '{marker}'")
    total = usage.ru_utime + usage.ru_stime
    print(f"{before:.3f} {max(0.0, total - before):.3f}")


if __name__ == "__main__":
    main()
