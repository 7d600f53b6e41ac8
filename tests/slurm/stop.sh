#!/usr/bin/env bash
# Stops the one-node Slurm that start.sh started (by its PID files) and the munge daemon.
STATE=${1:-/tmp/wiperlab-slurm}
for f in "$STATE/slurmd.pid" "$STATE/slurmctld.pid"; do
  [ -s "$f" ] && kill "$(cat "$f")" 2>/dev/null
done
if [ -s /run/munge/munged.pid ]; then kill "$(cat /run/munge/munged.pid)" 2>/dev/null; fi
exit 0
