#!/bin/bash
# A real single-node Slurm cluster on this machine (ctest slurm.single_node, label slow), from Debian's munge,
# slurmctld and slurmd (WARPCHECK_SLURM=1 scripts/setup.sh installs them), each with its own configuration,
# key, ports and state in a temporary directory. Through scripts/slurm/submit.sh it submits a battery in 4 shards
# and a worst-case search in 2 shards, requeues (preempts) battery shard 0 once it has finished a case, waits for
# the merge job, and checks that
#   - the requeued shard resumed from its file;
#   - the merged battery file equals an unsharded run of the same cases byte for byte (statistics, p-values,
#     corrected verdicts), and the report was written from it;
#   - the merged search's worst case is the best of its shards' and its chains their sum.
# It stops the daemons it started by their process ids. Usage: test_slurm.sh WARPCHECK_EXE
# Exit status 0 pass, 1 fail, 77 skipped (Slurm or munge not installed).
set -euo pipefail
exe=$(realpath "${1:?usage: test_slurm.sh WARPCHECK_EXE}")
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
for c in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$c" >/dev/null || { echo "SKIP: $c not installed (WARPCHECK_SLURM=1 scripts/setup.sh)"; exit 77; }
done
start=$(date +%s)
tmp=$(mktemp -d /tmp/warpcheck-slurm.XXXXXX)
chmod 755 "$tmp"  # munged wants its socket's directory searchable by every user
pids=()
stop_daemons() {
  local p
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.2; done
  done
}
cleanup() {
  stop_daemons
  if [[ "${WARPCHECK_SLURM_KEEP:-0}" == 1 ]]; then echo "kept $tmp"; else rm -rf "$tmp"; fi
}
trap cleanup EXIT

# Two free TCP ports for slurmctld and slurmd.
read -r ctld_port slurmd_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
host=$(hostname -s)
cpus=$(nproc)
mkdir -p "$tmp/state" "$tmp/spool" "$tmp/out"
head -c 1024 /dev/urandom >"$tmp/munge.key"
chmod 400 "$tmp/munge.key"
munged -F -f --key-file="$tmp/munge.key" --socket="$tmp/munge.socket" --pid-file="$tmp/munged.pid" \
  --log-file="$tmp/munged.log" --seed-file="$tmp/munged.seed" >"$tmp/munged.out" 2>&1 &
pids+=($!)
cat >"$tmp/slurm.conf" <<CONF
ClusterName=warpcheck-test
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$(id -un)
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge.socket
CredType=cred/munge
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=warpcheck Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$tmp/slurm.conf
for _ in $(seq 50); do [[ -S "$tmp/munge.socket" ]] && break; sleep 0.2; done
slurmctld -D -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" -N "$host" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
state=""
for _ in $(seq 100); do
  state=$(sinfo -h -o %T 2>/dev/null || true)
  [[ "$state" == idle ]] && break
  sleep 0.3
done
[[ "$state" == idle ]] || { echo "FAIL: the node is '$state', not idle"; tail -20 "$tmp"/slurm*.log; exit 1; }
echo "cluster up in $(($(date +%s) - start)) s (munged, slurmctld, slurmd: pids ${pids[*]})"

# Twelve cases at 2 10^5 samples in 4 shards of 3; a 3 s search in 2 shards.
selection=(--kernel sphere-solid-angle --config near --config grazing --config below-horizon
  --config partly-below-horizon --scalar float --scalar double --scalar "long double" --samples 200000 --seed 3
  --threads 1)
search=precision-sphere-solid-angle-double-angle
"$root/scripts/slurm/submit.sh" --out "$tmp/out" --warpcheck "$exe" --battery-shards 4 --search "$search" \
  --search-shards 2 --seconds 3 --search-args "--seed 5" -- "${selection[@]}" | tee "$tmp/submit.txt"
merge_job=$(sed -n 's/^merge: job \([0-9]*\).*/\1/p' "$tmp/submit.txt")
battery_job=$(sed -n 's/^battery: job array \([0-9]*\).*/\1/p' "$tmp/submit.txt")
# Preempt shard 0 as soon as its file holds a case: requeued, the task must resume from that file.
for _ in $(seq 600); do [[ -s "$tmp/out/battery-shard-0.json" ]] && break; sleep 0.1; done
scontrol requeue "${battery_job}_0"
# Slurm delays a requeued job's start (BeginTime); a preempted task on a real cluster waits for a free node.
for _ in $(seq 50); do
  scontrol update JobId="${battery_job}_0" StartTime=now 2>/dev/null && break
  sleep 0.2
done
deadline=$((SECONDS + 600))
while ((SECONDS < deadline)) && [[ -n "$(squeue -h 2>/dev/null)" ]]; do sleep 1; done
[[ -z "$(squeue -h)" ]] || { echo "FAIL: jobs still queued after 10 min"; squeue; exit 1; }
echo "jobs done in $(($(date +%s) - start)) s (merge job $merge_job)"

fail=0
if grep -q "resuming $tmp/out/battery-shard-0.json: [1-9]" "$tmp/out/battery-0.log"; then
  echo "ok: the requeued shard 0 resumed from its file ($(grep -o 'resuming.*' "$tmp/out/battery-0.log"))"
else
  echo "FAIL: the requeued shard 0 did not resume"
  cat "$tmp/out/battery-0.log"
  fail=1
fi
[[ -f "$tmp/out/battery.json" ]] || { echo "FAIL: no merged battery"; cat "$tmp/out/"*.log; exit 1; }
"$exe" validate "${selection[@]}" --quiet --json "$tmp/whole.json" >/dev/null || [[ $? -eq 1 ]]
if cmp -s "$tmp/out/battery.json" "$tmp/whole.json"; then
  echo "ok: the merged 4-shard battery equals the unsharded run byte for byte"
else
  echo "FAIL: the merged battery differs from the unsharded run"
  diff "$tmp/out/battery.json" "$tmp/whole.json" | head -20
  fail=1
fi
[[ -f "$tmp/out/html/index.html" ]] && echo "ok: report written" || { echo "FAIL: no report"; fail=1; }
python3 - "$tmp/out" <<'PY' || fail=1
import json, sys
out = sys.argv[1]
shards = [json.load(open(f"{out}/search-shard-{i}.json")) for i in range(2)]
merged = json.load(open(f"{out}/search.json"))
best = max(shards, key=lambda s: s["worst_error"])
ok = merged["worst_error_hex"] == best["worst_error_hex"] and merged["input"] == best["input"]
ok = ok and merged["chains"] == sum(s["chains"] for s in shards)
print(("ok" if ok else "FAIL") + ": merged search worst %s (shards %s), chains %d" %
      (merged["worst_error_hex"], [s["worst_error_hex"] for s in shards], merged["chains"]))
sys.exit(0 if ok else 1)
PY
echo "$(($(date +%s) - start)) s in all"
exit $fail
