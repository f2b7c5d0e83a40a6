#!/usr/bin/env bash
# End-to-end test of the Slurm scripts under a real single-node Slurm:
#
#   scripts/slurm/e2e.sh
#
# 1. installs Slurm and munge from the distribution's packages when they are missing
#    (apt-get: slurmctld slurmd slurm-client munge, and python3 for compare.py; needs root —
#    CI runs as root; the packages' services are kept from starting);
# 2. starts munged, slurmctld and slurmd in the foreground of background jobs, with their key,
#    sockets, state, spool, logs and pid files in a temporary directory (no systemd, no
#    cgroups: proctrack/linuxproc, task/none), one node (this host, its CPUs and memory) in
#    one partition;
# 3. submits the study with scripts/slurm/submit.sh (a job array of shards and the dependent
#    merge), waits for the merge, runs the same study as a single `counterpoise run`, and
#    compares the two results.json with scripts/slurm/compare.py (the run metadata: timings,
#    shard_timings, date, jobs and shards aside);
# 4. stops the daemons by their pids on exit, whatever happened.
#
# Fails (non-zero, saying why) if Slurm cannot be installed or started, a job fails, or the
# results differ. Settings (environment): COUNTERPOISE (the binary; default
# target/release/counterpoise, built if missing), E2E_CASE (default cases/two_link.json),
# E2E_SHARDS (default 2), E2E_ARGS (run options, e.g. "--dmax 2"), E2E_TIMEOUT (seconds to
# wait for the study, default 900), E2E_KEEP=1 keeps the temporary directory.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
here="$root/scripts/slurm"
case_file=${E2E_CASE:-$root/cases/two_link.json}
shards=${E2E_SHARDS:-2}
read -r -a run_args <<< "${E2E_ARGS:-}"
timeout=${E2E_TIMEOUT:-900}

say() { echo "e2e: $*"; }
fail() {
    echo "e2e: FAILED: $*" >&2
    exit 1
}

install_slurm() {
    local missing=() packages=(slurmctld slurmd slurm-client munge)
    for cmd in slurmctld slurmd sbatch squeue sinfo scontrol munged; do
        command -v "$cmd" >/dev/null 2>&1 || missing+=("$cmd")
    done
    # compare.py; a minimal Debian image has no Python
    if ! command -v python3 >/dev/null 2>&1; then
        missing+=(python3)
        packages+=(python3)
    fi
    if [[ ${#missing[@]} -eq 0 ]]; then
        return
    fi
    say "not installed: ${missing[*]}; installing ${packages[*]}"
    [[ $(id -u) -eq 0 ]] || fail "installing Slurm needs root (missing: ${missing[*]})"
    command -v apt-get >/dev/null 2>&1 ||
        fail "apt-get not found: install ${packages[*]} by hand"
    export DEBIAN_FRONTEND=noninteractive
    # The packages' own services must not start (no systemd here, and a system slurmctld or
    # slurmd would hold the ports): a policy-rc.d for the install, unless there is one.
    local policy=/usr/sbin/policy-rc.d ours=0
    if [[ ! -e $policy ]]; then
        printf '#!/bin/sh\nexit 101\n' > "$policy" && chmod 755 "$policy" && ours=1
    fi
    local status=0
    apt-get update -q || status=1
    if [[ $status -eq 0 ]]; then
        apt-get install -y -q "${packages[@]}" || status=2
    fi
    if [[ $ours -eq 1 ]]; then
        rm -f "$policy"
    fi
    [[ $status -ne 1 ]] || fail "apt-get update failed (no package repository reachable?)"
    [[ $status -ne 2 ]] || fail "apt-get install ${packages[*]} failed"
    for cmd in "${missing[@]}"; do
        command -v "$cmd" >/dev/null 2>&1 || fail "$cmd still missing after the install"
    done
}

install_slurm
bin=${COUNTERPOISE:-$root/target/release/counterpoise}
if [[ ! -x $bin ]]; then
    say "building $bin"
    (cd "$root" && cargo build --release --locked)
fi
[[ -x $bin ]] || fail "no counterpoise binary at $bin"
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
case_file=$(cd "$(dirname "$case_file")" && pwd)/$(basename "$case_file")

tmp=$(mktemp -d /tmp/counterpoise-slurm-e2e.XXXXXX)
# munged wants every directory above its socket searchable by all
chmod 711 "$tmp"
pids=()
cleanup() {
    local status=$?
    for pid in "${pids[@]}"; do
        kill "$pid" 2>/dev/null || true
    done
    for pid in "${pids[@]}"; do
        wait "$pid" 2>/dev/null || true
    done
    if [[ $status -ne 0 ]]; then
        for log in "$tmp"/*.log "$tmp"/study/logs/*.out; do
            [[ -f $log ]] || continue
            echo "---- $log (last 20 lines)" >&2
            tail -n 20 "$log" >&2
        done
    fi
    if [[ ${E2E_KEEP:-0} == 1 ]]; then
        say "kept $tmp"
    else
        rm -rf "$tmp"
    fi
    exit "$status"
}
trap cleanup EXIT

# munge: a private key and socket, so a munged of the system (if any) is left alone
dd if=/dev/urandom of="$tmp/munge.key" bs=1024 count=1 status=none
chmod 400 "$tmp/munge.key"
munged --foreground --key-file="$tmp/munge.key" --socket="$tmp/munge.socket" \
    --pid-file="$tmp/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge.seed" \
    --force >"$tmp/munged.out" 2>&1 &
pids+=($!)
for _ in $(seq 50); do
    [[ -S $tmp/munge.socket ]] && break
    sleep 0.1
done
[[ -S $tmp/munge.socket ]] || fail "munged did not start (see $tmp/munged.log)"

host=$(hostname -s)
cpus=$(nproc)
# 95 % of the memory, in MB: slurmd drains a node that has less than its RealMemory
memory=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.95 }' /proc/meminfo)
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$tmp/slurm.conf" <<CONF
ClusterName=counterpoise-e2e
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=${E2E_CTLD_PORT:-6817}
SlurmdPort=${E2E_SLURMD_PORT:-6818}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$tmp/munge.socket
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
MpiDefault=none
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=e2e Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$tmp/slurm.conf
slurmctld -D -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -f "$SLURM_CONF" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)

say "waiting for node $host to be idle"
state=
for _ in $(seq 120); do
    state=$(sinfo -h -N -n "$host" -o '%t' 2>/dev/null || true)
    [[ $state == idle ]] && break
    sleep 0.5
done
[[ $state == idle ]] || fail "node $host is '${state:-unreachable}', not idle, after 60 s"
sinfo

study=$tmp/study
say "submitting $(basename "$case_file") in $shards shards ${run_args[*]}"
started=$(date +%s.%N)
submitted=$(COUNTERPOISE=$bin "$here/submit.sh" "$case_file" "$shards" "$study" "${run_args[@]}")
echo "$submitted"
ids=$(tail -n 1 <<< "$submitted")
array=${ids#array=}
array=${array%% *}
merge=${ids##*merge=}

job_state() {
    scontrol show job "$1" -o 2>/dev/null | tr ' ' '\n' | sed -n 's/^JobState=//p' | sort -u |
        tr '\n' ' '
}
deadline=$(($(date +%s) + timeout))
while :; do
    merge_state=$(job_state "$merge")
    case $merge_state in
        "COMPLETED ") break ;;
        *FAILED* | *CANCELLED* | *TIMEOUT* | *NODE_FAIL* | *OUT_OF_MEMORY*)
            squeue -a || true
            fail "merge job $merge is $merge_state(shards: $(job_state "$array"))"
            ;;
    esac
    (($(date +%s) < deadline)) || fail "the study did not finish within $timeout s"
    sleep 1
done
finished=$(date +%s.%N)
say "shards: $(job_state "$array")— merge: $merge_state"
scontrol show job "$array" -o | tr ' ' '\n' | grep -E '^(JobId|ArrayTaskId|StartTime|EndTime)=' |
    paste -sd ' ' | sed 's/JobId=/\nJobId=/g' | sed '/^$/d' || true
say "sharded study: $(awk -v a="$started" -v b="$finished" 'BEGIN { printf "%.1f", b - a }') s from submission to merged results"

say "single run for comparison"
t0=$(date +%s.%N)
"$bin" run "$case_file" --out "$tmp/single" --quiet "${run_args[@]}" >/dev/null
t1=$(date +%s.%N)
say "single run: $(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.1f", b - a }') s"
python3 "$here/compare.py" "$tmp/single/results.json" "$study/results.json" ||
    fail "the merged results differ from the single run's"
say "OK"
