#!/bin/sh
# A one-node Slurm cluster on this machine, for the campaign tests (tests/slurm/README.md).
#
#   cluster.sh start DIR   starts munged, slurmctld and slurmd (as root: Debian 12's
#                          munge, slurmctld, slurmd, slurm-client) with their configuration,
#                          state, logs and pid files all in DIR; prints the SLURM_CONF to use
#   cluster.sh stop DIR    stops them by their pid files (never by name) and waits
#
# Nothing outside DIR is written: the cluster has its own munge socket and slurm.conf, so a
# munge or Slurm the machine already runs is left alone. No systemd and no cgroups are
# needed (linuxproc tracking, no task plugin).
set -eu
cmd=${1:-}; dir=${2:-}
[ -n "$cmd" ] && [ -n "$dir" ] || { echo "usage: $0 start|stop DIR" >&2; exit 2; }

pids() { for f in "$dir"/ctld.pid "$dir"/d.pid "$dir"/munge/munged.pid; do [ -s "$f" ] && cat "$f"; done; true; }

stop() {
  # The jobs first (a test that failed may leave some queued or running), then the daemons.
  if [ -s "$dir/ctld.pid" ] && kill -0 "$(cat "$dir/ctld.pid")" 2>/dev/null; then
    SLURM_CONF="$dir/slurm.conf" scancel --user="$(id -un)" 2>/dev/null || true
    for i in $(seq 1 50); do
      [ -z "$(SLURM_CONF="$dir/slurm.conf" squeue -h -o %i 2>/dev/null)" ] && break
      sleep 0.2
    done
  fi
  for p in $(pids); do kill "$p" 2>/dev/null || true; done
  # The daemons take a moment to go; wait for each, then make sure.
  for i in $(seq 1 50); do
    alive=0
    for p in $(pids); do kill -0 "$p" 2>/dev/null && alive=1; done
    [ $alive -eq 0 ] && break
    sleep 0.2
  done
  for p in $(pids); do kill -9 "$p" 2>/dev/null || true; done
  rm -f "$dir"/ctld.pid "$dir"/d.pid "$dir"/munge/munged.pid
}

case "$cmd" in
stop)
  [ -d "$dir" ] && stop
  exit 0
  ;;
start) ;;
*) echo "usage: $0 start|stop DIR" >&2; exit 2 ;;
esac

for exe in /usr/sbin/munged /usr/sbin/slurmctld /usr/sbin/slurmd /usr/bin/sbatch; do
  [ -x "$exe" ] || { echo "$exe is missing: apt-get install munge slurmctld slurmd slurm-client" >&2; exit 1; }
done
[ "$(id -u)" -eq 0 ] || { echo "the cluster's daemons start as root" >&2; exit 1; }
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
stop  # a cluster left in DIR by an earlier start goes first
mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
chown munge:munge "$dir/munge"
chmod 755 "$dir/munge"  # munged wants its socket reachable by every user
[ -s /etc/munge/munge.key ] || mungekey --create
su -s /bin/sh munge -c "/usr/sbin/munged --socket=$dir/munge/socket --pid-file=$dir/munge/munged.pid \
  --log-file=$dir/munge/munged.log --seed-file=$dir/munge/seed"

host=$(hostname)
cat > "$dir/slurm.conf" <<CONF
ClusterName=rocklab-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge/socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldLogFile=$dir/ctld.log
SlurmdLogFile=$dir/d.log
SlurmctldPidFile=$dir/ctld.pid
SlurmdPidFile=$dir/d.pid
SlurmctldPort=6917
SlurmdPort=6918
ReturnToService=2
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
NodeName=$host CPUs=$(nproc) RealMemory=$(awk '/MemTotal/ {print int($2 / 1024 * 0.8)}' /proc/meminfo) State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$dir/slurm.conf"
/usr/sbin/slurmctld -f "$SLURM_CONF"
/usr/sbin/slurmd -f "$SLURM_CONF"
# Up when the node takes jobs.
for i in $(seq 1 100); do
  state=$(sinfo -h -o %t 2>/dev/null || true)
  case "$state" in idle*|mix*|alloc*) echo "SLURM_CONF=$SLURM_CONF"; exit 0 ;; esac
  sleep 0.2
done
echo "the cluster did not come up (node state '$state'); logs in $dir" >&2
stop
exit 1
