#!/usr/bin/env bash
# stvl-bench sweep --emit slurm on a real, single-node Slurm (Debian's slurm-wlm and munge): this test starts
# munged (when none answers), slurmctld and slurmd with a private configuration under OUT, submits the emitted
# array with `sbatch --wait`, and requires every point's metrics.json with its own settings. Skips (77), saying
# why, only where a daemon cannot start.
set -euo pipefail
bin=$1 out=$2 scenario=$3
rm -rf "$out" && mkdir -p "$out"/{state,spool,log}
out=$(realpath "$out")
for tool in munged munge slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool is not installed (scripts/install-deps.sh installs slurm-wlm and munge)"; exit 1; }
done
skip() { echo "SKIP: $*"; exit 77; }
started=()
cleanup() {
  if [[ -n "${SLURM_CONF:-}" ]]; then
    scancel --quiet --user="$(id -un)" 2>/dev/null || true
    scontrol shutdown 2>/dev/null || true  # slurmctld and slurmd
  fi
  for p in "${started[@]}"; do kill "$p" 2>/dev/null || true; done
  [[ -n "${SLURM_CONF:-}" ]] && pkill -f "slurm(ctld|d) -f $SLURM_CONF" 2>/dev/null || true
}
trap cleanup EXIT

if ! munge -n >/dev/null 2>&1; then
  [[ -f /etc/munge/munge.key ]] || skip "no munge key (/etc/munge/munge.key)"
  mkdir -p /run/munge && chown munge:munge /run/munge 2>/dev/null || true
  if [[ $(id -u) -eq 0 ]]; then su -s /bin/sh munge -c munged 2>"$out/log/munged.err" || munged --force 2>>"$out/log/munged.err" || true
  else munged 2>"$out/log/munged.err" || true; fi
  for _ in $(seq 50); do munge -n >/dev/null 2>&1 && break; sleep 0.1; done
  munge -n >/dev/null 2>&1 || skip "munged cannot start: $(cat "$out/log/munged.err")"
  started+=("$(pgrep -n munged)")
fi

host=$(hostname)
port=$((16000 + $$ % 4000 * 2))
export SLURM_CONF="$out/slurm.conf"
cat >"$SLURM_CONF" <<CONF
ClusterName=stvltest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
StateSaveLocation=$out/state
SlurmdSpoolDir=$out/spool
SlurmctldPidFile=$out/slurmctld.pid
SlurmdPidFile=$out/slurmd.pid
SlurmctldLogFile=$out/log/slurmctld.log
SlurmdLogFile=$out/log/slurmd.log
SlurmUser=$(id -un)
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=stvl Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF" 2>"$out/log/slurmctld.err" || skip "slurmctld cannot start: $(cat "$out/log/slurmctld.err")"
for _ in $(seq 50); do [[ -s "$out/slurmctld.pid" ]] && break; sleep 0.1; done
[[ -s "$out/slurmctld.pid" ]] && started+=("$(cat "$out/slurmctld.pid")")
slurmd -f "$SLURM_CONF" 2>"$out/log/slurmd.err" || skip "slurmd cannot start: $(cat "$out/log/slurmd.err")"
for _ in $(seq 50); do [[ -s "$out/slurmd.pid" ]] && break; sleep 0.1; done
[[ -s "$out/slurmd.pid" ]] && started+=("$(cat "$out/slurmd.pid")")
for _ in $(seq 100); do sinfo -h -o %t 2>/dev/null | grep -q idle && break; sleep 0.2; done
sinfo -h -o %t 2>/dev/null | grep -q idle || skip "the Slurm node does not come up: $(tail -3 "$out/log/slurmctld.log" 2>/dev/null)"

"$bin" sweep "$scenario" --set duration_s=0.4 --set stop_at_path_end=false --set 'checks={}' \
  --option voxel-size=0.05,0.1 --seeds 1..2 --emit slurm --out "$out/grid" >/dev/null
timeout 600 sbatch --wait "$out/grid/sweep.sbatch" >"$out/sbatch.log" 2>&1 || { echo "FAIL: sbatch: $(cat "$out/sbatch.log")"; exit 1; }
"$bin" sweep --collect "$out/grid" >/dev/null
/usr/bin/python3 "$(dirname "$0")/check_sweep_points.py" "$out/grid" 4
n=$(ls "$out/grid" | grep -c '^slurm-')
((n == 4)) || { echo "FAIL: $n Slurm task logs, expected one per point"; exit 1; }
echo "PASS: the Slurm array ran 4 points, each with its own voxel size and seed"
