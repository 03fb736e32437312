#!/usr/bin/env bash
# test-local.sh RASTER - `raster batch` on a real scheduler: starts a single-node Slurm cluster on this
# machine (munged, slurmctld, slurmd from Debian; a minimal slurm.conf without cgroups, everything in a
# temporary folder, run as the current user), submits ci/slurm/render-array.sbatch as a 3-task array
# for a small manifest, waits, and checks that every output equals a direct `raster render` of the same
# job (ids and depth identical, colour identical), that each task rendered its own shard, and that a
# second submission skips every job. The daemons are stopped and the folder removed on any exit.
#
# Slurm missing is a failure, unless SR_ALLOW_MISSING_BACKENDS lists "slurm": then it exits 77
# (ctest's "skipped"). ci/setup installs it.
set -euo pipefail
raster=$(realpath "${1:?usage: $0 RASTER}")
src=$(cd "$(dirname "$0")/../.." && pwd)

for tool in munged slurmctld slurmd sbatch scontrol sinfo python3; do
    if ! command -v "$tool" >/dev/null; then
        if [[ ",${SR_ALLOW_MISSING_BACKENDS:-}," == *,slurm,* ]]; then
            echo "skipped: $tool is not installed and SR_ALLOW_MISSING_BACKENDS allows slurm to be absent"
            exit 77
        fi
        echo "FAIL: $tool is not installed (ci/setup installs slurmctld, slurmd, slurm-client, munge;" \
             "SR_ALLOW_MISSING_BACKENDS=slurm allows its absence)" >&2
        exit 1
    fi
done

# Short path: munge's socket must fit a sockaddr_un.
work=$(mktemp -d /tmp/sr-slurm.XXXXXX)
export SLURM_CONF=$work/slurm.conf
cleanup() {
    local rc=$?
    scontrol shutdown >/dev/null 2>&1 || true
    for pidfile in "$work/slurmd.pid" "$work/slurmctld.pid" "$work/munge/munged.pid"; do
        [ -s "$pidfile" ] || continue
        pid=$(cat "$pidfile")
        kill "$pid" 2>/dev/null || true
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true
    done
    if [ "$rc" -ne 0 ]; then
        for log in "$work"/log/*.log "$work"/out/*.out; do
            [ -f "$log" ] && { echo "---- $log"; tail -n 30 "$log"; }
        done
    fi
    rm -rf "$work"
    exit "$rc"
}
trap cleanup EXIT

mkdir -p "$work/munge" "$work/state" "$work/spool" "$work/log" "$work/out"
chmod 700 "$work/munge"
# A fresh key for this cluster alone.
head -c 1024 /dev/urandom >"$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
munged --force --socket="$work/munge/sock" --key-file="$work/munge/munge.key" \
    --log-file="$work/log/munged.log" --pid-file="$work/munge/munged.pid" --seed-file="$work/munge/seed"

# Two free TCP ports for the daemons.
read -r ctld_port d_port < <(python3 -c '
import socket
s = [socket.socket() for _ in range(2)]
for x in s: x.bind(("127.0.0.1", 0))
print(*[x.getsockname()[1] for x in s])')
host=$(hostname -s)
user=$(id -un)
cat >"$SLURM_CONF" <<CONF
ClusterName=rastertest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/sock
SlurmUser=$user
SlurmdUser=$user
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/log/slurmctld.log
SlurmdLogFile=$work/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=1000 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 100); do
    state=$(sinfo -h -n "$host" -o %t 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.2
done
[ "$state" = idle ] || { echo "FAIL: the node did not come up (state '$state')" >&2; exit 1; }

# The manifest: a turntable with AOVs and two single frames, 7 frames for 3 tasks.
jobs=$work/jobs
mkdir -p "$jobs"
cat >"$jobs/m.jsonl" <<'JOBS'
{"defaults": {"width": 64, "height": 48}}
{"scene": "builtin", "orbit": "0:150", "frames": 5, "camera": "orbit:0,20,9", "output": "out/t_%d.png", "aov": "out/t_%d.exr"}
{"scene": "builtin", "camera": "orbit:30,-10,7", "msaa": 4, "output": "out/a.png", "aov": "out/a.exr"}
{"scene": "builtin:dense", "shading": "normals", "output": "out/d.png", "aov": "out/d.exr"}
JOBS
export RASTER=$raster SUMMARY_DIR=$work/summaries
submit() {
    sbatch --wait --array=0-2 --chdir="$jobs" --output="$work/out/task-%a.out" \
        "$src/ci/slurm/render-array.sbatch" m.jsonl --backend vulkan
}
start=$(date +%s)
submit
echo "array of 3 tasks done in $(($(date +%s) - start)) s"

# Each task rendered its shard of the 7 frames (3, 2, 2), all of them together.
python3 - "$SUMMARY_DIR" <<'PY'
import json, glob, sys
rows = [json.load(open(f)) for f in sorted(glob.glob(sys.argv[1] + "/summary-*.json"))]
assert len(rows) == 3, f"{len(rows)} summaries"
shards = sorted((r["shard"]["index"], r["shard"]["count"], r["shard"]["source"], r["rendered"], r["failed"]) for r in rows)
assert shards == [(0, 3, "slurm", 3, 0), (1, 3, "slurm", 2, 0), (2, 3, "slurm", 2, 0)], shards
print("shards:", shards)
PY

# Every output against a direct render of the same job.
direct=$work/direct
mkdir -p "$direct"
check() {  # NAME ARGS...: out/NAME.{png,exr} equal `raster render ARGS`
    local name=$1
    shift
    "$raster" render -q --backend vulkan --width 64 --height 48 "$@" -o "$direct/$name.png" --aov "$direct/$name.exr"
    "$raster" compare "$jobs/out/$name.png" "$direct/$name.png" >/dev/null
    "$raster" compare "$jobs/out/$name.exr" "$direct/$name.exr" >/dev/null
    echo "$name: identical to raster render $*"
}
# Frame k of orbit 0:150 over 5 frames sits at azimuth 37.5 k.
azimuths=(0 37.5 75 112.5 150)
for k in 0 1 2 3 4; do check "t_$k" --camera "orbit:${azimuths[k]},20,9"; done
check a --camera orbit:30,-10,7 --msaa 4
check d builtin:dense --shading normals

# A second submission finds every job done.
rm -rf "$SUMMARY_DIR"
submit
python3 - "$SUMMARY_DIR" <<'PY'
import json, glob, sys
rows = [json.load(open(f)) for f in glob.glob(sys.argv[1] + "/summary-*.json")]
assert len(rows) == 3 and sum(r["jobs"]["skipped"] for r in rows) == 7 and sum(r["rendered"] for r in rows) == 0, rows
print("resubmitted: all 7 jobs skipped")
PY
echo "PASS"
