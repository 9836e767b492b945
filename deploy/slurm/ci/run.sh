#!/usr/bin/env bash
# The CI's test of deploy/slurm/campaign.sbatch on a real Slurm (docs/campaigns.md): starts
# munged, slurmctld and slurmd for a one-node cluster on localhost (deploy/slurm/ci/slurm.conf.in,
# everything in one temporary folder), submits the shipped sbatch for the campaign
# host-sim/campaigns/ci-small.campaign.toml in 4 shards with `sbatch --wait`, waits for its
# dependent merge job, and checks that the merged report is the one-machine run's, byte for
# byte. Stops the daemons however it ends. Needs root (slurmd) and Debian's slurm-wlm and munge
# (scripts/setup.sh). Bounded: each wait has a deadline, and a daemon that does not come up is
# named with the end of its log.
#
#   bash deploy/slurm/ci/run.sh [HOST_SIM]   # default: target/host/host-sim
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
cd "$root"
host_sim=$(realpath -m "${1:-target/host/host-sim}")
campaign="$root/host-sim/campaigns/ci-small.campaign.toml"
shards=4

fail() { echo "slurm-ci: FAILED: $*" >&2; exit 1; }
if [ ! -x "$host_sim" ] && [ "$host_sim" = "$root/target/host/host-sim" ]; then
  echo "slurm-ci: building host-sim (cargo build --profile host -p host-sim)"
  cargo build --profile host -p host-sim
fi
if [ "$(id -u)" -ne 0 ]; then
  # slurmd runs each job as its user: it needs root.
  command -v sudo >/dev/null || fail "needs root (slurmd runs jobs as their user), and there is no sudo"
  exec sudo -E bash "$0" "$host_sim"
fi
for cmd in munged slurmctld slurmd sbatch squeue scontrol sinfo; do
  command -v "$cmd" >/dev/null || fail "$cmd not found: install slurm-wlm and munge (scripts/setup.sh)"
done
[ -x "$host_sim" ] || fail "$host_sim not found: build it first (cargo build --profile host -p host-sim)"

dir=$(mktemp -d /tmp/host-sim-slurm-ci.XXXXXX)
chmod 755 "$dir"
pids=()
stop() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do
    for _ in $(seq 50); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$p" 2>/dev/null || true
  done
  if [ "${keep:-0}" = 1 ]; then echo "slurm-ci: logs kept in $dir" >&2; else rm -rf "$dir"; fi
}
trap stop EXIT
keep=1

# A free TCP port (the system's pick) for each daemon.
port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }
mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/work"
chmod 700 "$dir/munge"
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$dir/munge/munge.key"
sed -e "s|@DIR@|$dir|g" -e "s|@USER@|$(id -un)|g" -e "s|@CPUS@|$(nproc)|g" \
  -e "s|@CTLD_PORT@|$(port)|g" -e "s|@SLURMD_PORT@|$(port)|g" \
  deploy/slurm/ci/slurm.conf.in > "$dir/slurm.conf"
export SLURM_CONF="$dir/slurm.conf"

# Waits up to $2 s for the command $5… to succeed while daemon $1 (pid $3) lives; else names
# the daemon, says whether it died, and shows the end of its log and of its output ($4: both
# files, `log:out`).
wait_for() {
  local what=$1 secs=$2 pid=$3 files=$4; shift 4
  local end=$((SECONDS + secs)) why=""
  until "$@" >/dev/null 2>&1; do
    if ! kill -0 "$pid" 2>/dev/null; then
      why="exited"
    elif [ "$SECONDS" -ge "$end" ]; then
      why="did not come up within ${secs} s"
    fi
    if [ -n "$why" ]; then
      echo "slurm-ci: $what $why; the end of its log and output:" >&2
      for f in ${files//:/ }; do
        [ -s "$f" ] && { echo "--- $f" >&2; tail -n 20 "$f" >&2; }
      done
      fail "$what $why"
    fi
    sleep 0.2
  done
}

t0=$SECONDS
munged --foreground --force --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
  --pid-file="$dir/munge/munged.pid" --seed-file="$dir/munge/munged.seed" \
  --log-file="$dir/munge/munged.log" 2>"$dir/munge/munged.stderr" &
pids+=($!)
wait_for munged 15 "${pids[-1]}" "$dir/munge/munged.log:$dir/munge/munged.stderr" \
  munge --socket="$dir/munge/munge.socket" -n
slurmctld -D -i -f "$SLURM_CONF" >"$dir/slurmctld.stdout" 2>&1 &
pids+=($!)
wait_for slurmctld 30 "${pids[-1]}" "$dir/slurmctld.log:$dir/slurmctld.stdout" scontrol ping
slurmd -D -N localhost -f "$SLURM_CONF" >"$dir/slurmd.stdout" 2>&1 &
pids+=($!)
idle() { sinfo -h -n localhost -o %t | grep -qx idle; }
wait_for slurmd 30 "${pids[-1]}" "$dir/slurmd.log:$dir/slurmd.stdout" idle
echo "slurm-ci: munged, slurmctld and slurmd up in $((SECONDS - t0)) s ($(sinfo -h -o '%P %D %c %t'))"

# The campaign on the cluster: the array (one shard per task), then its merge.
work="$dir/work"
cd "$work"
export HOST_SIM="$host_sim"
timeout 300 sbatch --wait --array=0-$((shards - 1)) --output="$work/shard-%a.out" \
  "$root/deploy/slurm/campaign.sbatch" "$campaign" "$work/cluster" \
  || { tail -n 20 "$work"/shard-*.out >&2 || true; fail "the array job did not succeed"; }
merge_job=$(cat "$work/cluster/merge.jobid" 2>/dev/null) || fail "no merge job was submitted"
end=$((SECONDS + 120))
while squeue -h -j "$merge_job" 2>/dev/null | grep -q .; do
  [ "$SECONDS" -lt "$end" ] || fail "the merge job $merge_job did not end within 120 s"
  sleep 0.5
done
[ "$(cat "$work/cluster/merge.exit" 2>/dev/null)" = 0 ] \
  || { cat "$work/cluster/merge.out" >&2 || true; fail "the merge job did not exit 0"; }
echo "slurm-ci: $shards shards and the merge ran on Slurm in $((SECONDS - t0)) s"

# The same campaign on one machine, without Slurm; the reports must be the same bytes (but the
# folder's lock file, which names its process).
"$host_sim" campaign run "$campaign" --shard 0/1 --out "$work/one/shard-0" >"$work/one.log" 2>&1
"$host_sim" campaign merge "$work/one/shard-0" --out "$work/one/report" >/dev/null
diff -r -x host-sim.lock "$work/one/report" "$work/cluster/report" \
  || fail "the report merged from Slurm's shards differs from the one-machine run's"
ls "$work/cluster/report/worst-max_path.toml" >/dev/null
echo "slurm-ci: the merged report equals the one-machine run's byte for byte ($(ls "$work/cluster/report" | wc -l) files); total $((SECONDS - t0)) s"
keep=0
