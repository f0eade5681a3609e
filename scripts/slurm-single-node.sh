#!/usr/bin/env bash
# Starts a one-node Slurm cluster on this machine (munged, slurmctld and
# slurmd, all as root), for the Slurm round trip test
# (crates/whitted-cli/tests/slurm.rs, recipe in docs/cluster.md).
#
# Installs Debian's slurm-wlm and munge if they are missing. Safe to run
# again: what is running already is left running. Needs root (or sudo
# without a password); otherwise it says so and does nothing, and the test
# then skips.
set -euo pipefail

if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  as_root=(sudo -n)
else
  echo "slurm-single-node: SKIPPED: not root and no password-less sudo; the Slurm test will skip" >&2
  exit 0
fi
run() { "${as_root[@]}" "$@"; }

if ! command -v slurmctld >/dev/null 2>&1 || ! command -v munged >/dev/null 2>&1; then
  run env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
      slurm-wlm munge >/dev/null ||
    { run apt-get update -q >/dev/null &&
      run env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
        slurm-wlm munge >/dev/null; }
fi

host=$(hostname -s)
cpus=$(nproc)
run mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm /run/munge
conf=$(cat <<CONF
# A one-node cluster for whitted's tests (scripts/slurm-single-node.sh).
ClusterName=whitted-test
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
# Start a batch job as soon as it may run, not up to 3 s later (the
# default): the test's jobs take a fraction of a second.
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
)
if [ "$(cat /etc/slurm/slurm.conf 2>/dev/null || true)" != "$conf" ]; then
  printf '%s\n' "$conf" | run tee /etc/slurm/slurm.conf >/dev/null
  changed=1
else
  changed=0
fi

# munge: a key, then the daemon (as its own user, as the package means).
if ! run test -s /etc/munge/munge.key; then
  run mkdir -p /etc/munge
  run dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none
fi
run chown -R munge:munge /etc/munge /run/munge /var/lib/munge /var/log/munge 2>/dev/null || true
run chmod 400 /etc/munge/munge.key
if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
  run runuser -u munge -- /usr/sbin/munged
  for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
fi

# A daemon started by this script before a change of slurm.conf is told to
# read it again.
if [ "$changed" = 1 ] && scontrol ping >/dev/null 2>&1; then
  run scontrol reconfigure || true
fi
if ! scontrol ping 2>/dev/null | grep -q UP; then
  run /usr/sbin/slurmctld
  for _ in $(seq 100); do scontrol ping 2>/dev/null | grep -q UP && break; sleep 0.1; done
fi
if ! run test -e /run/slurmd.pid || ! run kill -0 "$(run cat /run/slurmd.pid)" 2>/dev/null; then
  run /usr/sbin/slurmd
fi

# Wait for the node to take jobs; a node left down by an earlier run is
# brought back.
for _ in $(seq 100); do
  state=$(sinfo -h -n "$host" -o %T 2>/dev/null | head -1)
  case "$state" in
    idle*|mixed*|allocated*) echo "slurm-single-node: $host is $state ($cpus CPUs)"; exit 0 ;;
    down*|drain*|fail*) run scontrol update nodename="$host" state=resume 2>/dev/null || true ;;
  esac
  sleep 0.2
done
echo "slurm-single-node: the node $host did not come up (state: ${state:-unknown}); see /var/log/slurm/" >&2
exit 1
