#!/usr/bin/env bash
# Run a small configuration of the workflow through Snakemake's SLURM executor on a real
# one-node SLURM started here, run the same configuration locally, and check the result tables
# are equal. Usage (root, from anywhere; `make slurm-test` builds the environments first):
#
#   .ci/slurm_test.sh
#
# Steps: install Debian's slurmctld slurmd slurm-client munge if missing; write
# /etc/slurm/slurm.conf (removed again on exit); start munged (unless one already answers),
# slurmctld and slurmd on localhost; wait for the node to be idle; run the targets through
# workflow/profiles/slurm in one scratch copy of the repository and with the default profile in
# another; compare (.ci/slurm_compare.py), check the jobs (.ci/slurm_jobs.py); stop exactly the
# daemons it started, by PID, on every exit. Every wait is bounded; a failure names what did not
# come up and prints the SLURM logs.
#
# Environment: SLURM_TEST_CONFIG (default config/small.yaml), SLURM_TEST_TARGETS (default
# "fig2a fig7a": both sweeps run in chunks, so several simulate jobs go to SLURM),
# SLURM_TEST_TIMEOUT (seconds for the SLURM run, default 900), SLURM_TEST_POLL (seconds between
# the executor's status checks, default 5: a private cluster, not the shared one the profile's
# 40 s is meant for), SLURM_TEST_ARGS (more options for the SLURM run's snakemake),
# SLURM_TEST_KEEP=1 keeps the scratch directory.
set -euo pipefail

cd "$(dirname "${BASH_SOURCE[0]}")/.."
repo=$PWD
config=${SLURM_TEST_CONFIG:-config/small.yaml}
read -r -a targets <<<"${SLURM_TEST_TARGETS:-fig2a fig7a}"
run_timeout=${SLURM_TEST_TIMEOUT:-900}
poll=${SLURM_TEST_POLL:-5}
read -r -a extra_args <<<"${SLURM_TEST_ARGS:-}"
packages=(slurmctld slurmd slurm-client munge)
unset PYTHONDONTWRITEBYTECODE # byte-compiled imports: snakemake starts in ~2 s, not ~15 s
export MPLBACKEND=Agg

say() { printf '[slurm-test %s] %s\n' "$(date -u +%H:%M:%S)" "$*"; }
fail() {
    say "FAILED: $*" >&2
    exit 1
}

# --- preconditions -------------------------------------------------------------------------------
[ "$(id -u)" -eq 0 ] || fail "must run as root (it installs packages and starts SLURM daemons)"
for venv in .venv .venv-cluster; do
    [ -x "$venv/bin/snakemake" ] || fail "$venv/bin/snakemake missing: run 'make env cluster-env'"
done
[ -f "$config" ] || fail "configuration $config not found (set SLURM_TEST_CONFIG)"
config=$(realpath "$config")
# Local and SLURM runs must use the same library versions for their outputs to be comparable.
if ! diff <(grep -E '^[A-Za-z0-9]' requirements.lock) \
    <(grep -E '^[A-Za-z0-9]' requirements-cluster.lock | grep -v '^snakemake-executor-plugin-slurm') \
    >/dev/null; then
    fail "requirements-cluster.lock pins differ from requirements.lock: run 'make cluster-lock'"
fi
.venv-cluster/bin/python -c 'import snakemake_executor_plugin_slurm' 2>/dev/null ||
    fail ".venv-cluster lacks the SLURM executor plugin: run 'make cluster-env'"
if .venv/bin/python -c 'import snakemake_executor_plugin_slurm' 2>/dev/null; then
    fail ".venv has the SLURM executor plugin: local runs would pay for it (rebuild: make env)"
fi
for daemon in slurmctld slurmd; do
    if pid=$(pgrep -x "$daemon"); then
        fail "a $daemon is already running (PID $pid); this test starts its own and will not touch it"
    fi
done
partition=$(.venv/bin/python -c '
import sys, yaml
print(yaml.safe_load(open(sys.argv[1]))["default-resources"]["slurm_partition"])
' workflow/profiles/slurm/config.yaml)

# --- packages ------------------------------------------------------------------------------------
missing=()
for package in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q 'install ok installed' ||
        missing+=("$package")
done
if [ "${#missing[@]}" -gt 0 ]; then
    say "installing ${missing[*]} (apt-get)"
    export DEBIAN_FRONTEND=noninteractive
    apt_install() {
        timeout 600 apt-get install -y -q --no-install-recommends "${packages[@]}" >/dev/null
    }
    # A clean machine may have no package lists yet: update once, then retry.
    apt_install || { timeout 300 apt-get update -q >/dev/null && apt_install; } ||
        fail "apt-get could not install ${packages[*]}"
else
    say "SLURM packages already installed: $(dpkg-query -W -f='${Version}' slurmctld)"
fi

# --- scratch state, private slurm.conf -----------------------------------------------------------
state=$(mktemp -d /tmp/restitution-slurm.XXXXXX)
started=()    # "name:pid" of every daemon this script started, stopped in this order reversed
exit_ok=false # set just before a successful exit
# The default path, not SLURM_CONF: the executor's job step removes SLURM_* variables before its
# nested srun, which then finds no configuration (plugin 2.8.0 with jobstep 0.6.1).
conf=/etc/slurm/slurm.conf
marker="# One-node test cluster of .ci/slurm_test.sh"
wrote_conf=false
child="" # PID of the `timeout` running a snakemake, while one runs

stop_daemons() {
    local i entry name pid
    for ((i = ${#started[@]} - 1; i >= 0; i--)); do
        entry=${started[i]}
        name=${entry%%:*}
        pid=${entry#*:}
        kill -0 "$pid" 2>/dev/null || continue
        say "stopping $name (PID $pid)"
        kill -TERM "$pid" 2>/dev/null || true
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.2
        done
        if kill -0 "$pid" 2>/dev/null; then
            say "$name (PID $pid) ignored SIGTERM for 10 s: SIGKILL"
            kill -KILL "$pid" 2>/dev/null || true
        fi
    done
}

cleanup() {
    local status=$?
    set +e
    trap - EXIT INT TERM
    if [ -n "$child" ] && kill -0 "$child" 2>/dev/null; then
        say "interrupted: stopping the running snakemake (timeout PID $child, SIGKILL after 20 s)"
        kill -TERM "$child"
        wait "$child"
    fi
    if [ "$exit_ok" != true ]; then
        status=$((status == 0 ? 1 : status))
        if [ "$wrote_conf" = true ]; then
            say "jobs known to the test cluster:"
            timeout 10 squeue -t all -o '%i %k %T %R' 2>&1 | sed 's/^/    /'
            # Running job steps outlive slurmd: cancel them while the controller still answers.
            timeout 10 scancel --partition "$partition" 2>/dev/null
            for _ in $(seq 30); do
                [ -z "$(timeout 5 squeue -h -t running,completing -o %i 2>/dev/null)" ] && break
                sleep 0.5
            done
        fi
        for log in "$state"/slurmctld.log "$state"/slurmctld.out "$state"/slurmd.log \
            "$state"/slurmd.out /var/log/munge/munged.log; do
            [ -s "$log" ] || continue
            say "last lines of $log:"
            tail -n 40 "$log" | sed 's/^/    /'
        done
    fi
    stop_daemons
    # A slurm.conf naming a controller that is gone makes every SLURM client call, and so every
    # snakemake start with the executor plugin installed, wait ~9 s (notes/cluster-slurm.md).
    if [ "$wrote_conf" = true ]; then
        rm -f "$conf"
    fi
    if [ "$exit_ok" = true ] && [ "${SLURM_TEST_KEEP:-0}" != 1 ]; then
        rm -rf "$state"
    else
        say "scratch directory kept: $state"
    fi
    exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

node=$(hostname -s)
cpus=$(nproc)
# Well below the machine's memory (slurmd refuses a node that has less than configured).
mem_total=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 }' /proc/meminfo)
real_memory=$((mem_total / 2 < 8000 ? mem_total / 2 : 8000))
mkdir -p "$state/ctld" "$state/spool"
# Never overwrite a site's configuration; one left by an interrupted run of this script is fine.
if [ -e "$conf" ] && ! head -n 1 "$conf" | grep -qF "$marker"; then
    fail "$conf exists and was not written by this script: not touching a real SLURM set-up"
fi
mkdir -p "$(dirname "$conf")"
wrote_conf=true
cat >"$conf" <<EOF
$marker (removed when it exits).
# notes/cluster-slurm.md: no cgroups, no accounting.
ClusterName=restitution-test
SlurmctldHost=$node(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
ReturnToService=2
# Finished jobs stay visible to squeue (the profile's status command) for this many seconds.
MinJobAge=300
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/slurmctld.log
SlurmdLogFile=$state/slurmd.log
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$real_memory State=UNKNOWN
PartitionName=$partition Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF

# wait_for SECONDS WHAT COMMAND...: poll COMMAND every 0.5 s; fail naming WHAT after SECONDS.
wait_for() {
    local seconds=$1 what=$2
    shift 2
    local deadline=$((SECONDS + seconds))
    until timeout 10 "$@" >/dev/null 2>&1; do
        [ "$SECONDS" -lt "$deadline" ] || fail "$what did not come up within $seconds s"
        sleep 0.5
    done
}

# --- munge ---------------------------------------------------------------------------------------
if timeout 5 bash -c 'munge -n | unmunge' >/dev/null 2>&1; then
    say "a munged already answers: using it (and leaving it running)"
else
    if [ ! -s /etc/munge/munge.key ]; then
        say "creating /etc/munge/munge.key"
        mungekey --create --keyfile=/etc/munge/munge.key
        chown munge:munge /etc/munge/munge.key
        chmod 0400 /etc/munge/munge.key
    fi
    install -d -o munge -g munge -m 0755 /run/munge
    rm -f /run/munge/munged.pid
    runuser -u munge -- munged || fail "munged did not start (see /var/log/munge/munged.log)"
    wait_for 10 "munged's pid file /run/munge/munged.pid" test -s /run/munge/munged.pid
    started+=("munged:$(cat /run/munge/munged.pid)")
    wait_for 20 "munged (munge -n | unmunge)" bash -c 'munge -n | unmunge'
fi

# --- slurmctld, slurmd ---------------------------------------------------------------------------
# In the foreground (-D) as children of this script, so $! is the daemon's own PID.
slurmctld -D -f "$conf" >"$state/slurmctld.out" 2>&1 &
started+=("slurmctld:$!")
wait_for 60 "slurmctld (scontrol ping)" bash -c 'scontrol ping | grep -q "is UP"'
slurmd -D -f "$conf" >"$state/slurmd.out" 2>&1 &
started+=("slurmd:$!")
wait_for 60 "node $node idle in partition $partition (sinfo)" \
    bash -c '[ "$(sinfo -h -n "$1" -o %t)" = idle ]' _ "$node"
say "SLURM up: node $node idle, $cpus CPUs, ${real_memory} MB, partition $partition"

# --- the two runs --------------------------------------------------------------------------------
# Scratch copies of the repository's files (no environments, results or snakemake state); the
# committed figures are removed so that they are really rebuilt. The package itself is imported
# from this checkout (editable installs of .venv and .venv-cluster).
copy_repo() {
    mkdir -p "$1"
    tar -C "$repo" -cf - --exclude=./.git --exclude='./.venv*' --exclude=./.cache \
        --exclude=./results --exclude=./logs --exclude=./runs --exclude=./.snakemake \
        --exclude=__pycache__ . |
        tar -C "$1" -xf -
    rm -f "$1"/figures/*.png "$1"/figures/*.pdf
}
copy_repo "$state/slurm"
copy_repo "$state/local"

# bounded LOG COMMAND...: run COMMAND in the background under `timeout`, output to LOG, and wait
# for it. In the background because bash runs a signal's trap only after a foreground command
# ends: `wait` returns at once, and cleanup stops the run. -k: without accounting, a
# misconfigured status command makes snakemake ignore SIGTERM.
bounded() {
    local log=$1
    shift
    NUMBA_CACHE_DIR=$PWD/.cache/numba timeout -k 20 "$run_timeout" "$@" >"$log" 2>&1 &
    child=$!
    local status=0
    wait "$child" || status=$?
    child=""
    return "$status"
}

say "SLURM run: snakemake --workflow-profile workflow/profiles/slurm ${targets[*]} (--configfile $config)"
cd "$state/slurm"
t0=$SECONDS
bounded "$state/slurm-run.log" "$repo/.venv-cluster/bin/snakemake" \
    --workflow-profile workflow/profiles/slurm \
    --slurm-init-seconds-before-status-checks "$poll" "${extra_args[@]}" "${targets[@]}" \
    --configfile "$config" || {
    status=$?
    tail -n 60 "$state/slurm-run.log" | sed 's/^/    /'
    if [ "$status" -eq 124 ] || [ "$status" -eq 137 ]; then
        fail "the SLURM run did not finish within $run_timeout s (log: $state/slurm-run.log)"
    fi
    fail "the SLURM run failed with status $status (log: $state/slurm-run.log)"
}
slurm_seconds=$((SECONDS - t0))
# Finished jobs stay in squeue for MinJobAge (300 s): they are the record of what ran where.
squeue -h -t all -o '%i|%k|%T|%V|%S|%e|%C|%m|%l' >"$state/squeue.txt"
grep -q "Using workflow specific profile workflow/profiles/slurm" "$state/slurm-run.log" ||
    fail "the SLURM run did not use workflow/profiles/slurm (see $state/slurm-run.log)"
say "SLURM run done in ${slurm_seconds} s"

say "local run: snakemake ${targets[*]} (default profile, -c2)"
cd "$state/local"
t0=$SECONDS
bounded "$state/local-run.log" "$repo/.venv/bin/snakemake" "${targets[@]}" --configfile "$config" ||
    fail "the local run failed with status $? (log: $state/local-run.log)"
local_seconds=$((SECONDS - t0))
say "local run done in ${local_seconds} s"
cd "$repo"

# --- checks --------------------------------------------------------------------------------------
# A named run (config key `run`, e.g. small) writes under runs/<run>/ (docs/runs.md).
run_dir() {
    local found
    found=$(find "$1/runs" -mindepth 1 -maxdepth 1 -type d 2>/dev/null | head -n 1)
    echo "${found:-$1}"
}
.venv/bin/python .ci/slurm_compare.py "$(run_dir "$state/local")" "$(run_dir "$state/slurm")"
.venv/bin/python .ci/slurm_jobs.py "$state/squeue.txt" "$(run_dir "$state/slurm")" \
    "$local_seconds" "$slurm_seconds"
exit_ok=true
say "PASSED"
