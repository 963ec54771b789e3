#!/usr/bin/env bash
# ci/cluster_test.sh MINER_BINARY — campaigns and datasets scale out for real (REQ-REPORT-007).
#
# cites: REQ-REPORT-007
#
# On this machine, as a single-node Slurm cluster (ci/slurm_setup.sh starts it if `sinfo`
# does not show a usable node) and with GNU parallel, in a temporary folder:
#   (a) a `bench frontend` campaign as a Slurm array job (--shard i/3), merged with
#       `miner bench merge`, equals the unsharded campaign: every run record and summary,
#       the wall-clock fields aside (*time_ms*, *_ms, total_s, *_per_s);
#   (b) a `miner dataset` as a Slurm array job, merged with `miner dataset --merge`, is
#       byte-identical to the unsharded folder (diff -r);
#   (c) the GNU parallel recipe of docs/report.md brings its parts back to the current
#       folder and merges like (a), run with the local host (-S :), with a "remote" host
#       reached through a stand-in for ssh (--ssh; it runs the command on this machine in a
#       separate home folder), so that --basefile, --return and --cleanup really move files
#       with rsync, and with both (-S 1/:,1/standin).
# Exits non-zero with a message naming the first mismatch. Registered with ctest under the
# label `cluster` (not run by default: `ctest --test-dir build/release -L cluster`).
# The binary is copied first, so a rebuild during the test cannot mix two binaries.
# MINER_CLUSTER_DIR: where to make the temporary folder (default $TMPDIR or /tmp); it is
# removed on success and kept on failure.
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
say() { echo "cluster_test: $*"; }
fail() { echo "cluster_test: FAIL: $*" >&2; exit 1; }

[ $# -eq 1 ] || { echo "usage: $0 MINER_BINARY" >&2; exit 2; }
[ -x "$1" ] || fail "$1 is not an executable"
for tool in python3 diff timeout; do command -v "$tool" >/dev/null || fail "$tool is missing"; done

work=$(mktemp -d "${MINER_CLUSTER_DIR:-${TMPDIR:-/tmp}}/miner-cluster.XXXXXX")
chmod 0755 "$work"
finish() {
  local rc=$?
  if [ $rc -eq 0 ]; then rm -rf "$work"; else echo "cluster_test: files kept in $work" >&2; fi
}
trap finish EXIT
cp "$1" "$work/miner"
M="$work/miner"
cd "$work"
t0=$SECONDS

# --- Slurm up? -------------------------------------------------------------------------
node_ok() { sinfo -h -N -o '%T' 2>/dev/null | grep -Eqx 'idle|mixed|allocated'; }
if ! node_ok || ! command -v parallel >/dev/null || ! command -v rsync >/dev/null; then
  say "no usable Slurm node (or GNU parallel / rsync missing): running ci/slurm_setup.sh"
  bash "$here/slurm_setup.sh" || fail "ci/slurm_setup.sh failed"
fi
node_ok || fail "Slurm has no idle node after ci/slurm_setup.sh (sinfo: $(sinfo 2>&1 | tr '\n' ' '))"
# sinfo still shows a node idle for SlurmdTimeout after its slurmd died: run one step first.
timeout 120 srun --time=1 --job-name="miner-probe-$$" true \
  || fail "Slurm does not run a job step (is slurmd up? bash ci/slurm_setup.sh --status)"
say "slurm: $(sinfo -h -o '%P %a %D %T' | head -n 1); $(parallel --version | head -n 1)"

N=3
CAMPAIGN=(--runs 6 --planners "rrtstar,informed,ompl:RRTstar" --throughput-iterations 0)
DATASET=(--preset indoor --count 4 --test-count 2 --shard-size 1 --seed 3)

# run_array NAME SCRIPT: the job script as a Slurm array, waits; fails if any task fails.
run_array() {
  local name=$1 script=$2 out rc=0
  out=$(timeout 600 sbatch --parsable --wait --job-name="miner-$name-$$" "$script" 2>&1) || rc=$?
  if [ $rc -ne 0 ]; then
    scancel --name="miner-$name-$$" 2>/dev/null || true
    for f in slurm-"$name"-*.out; do [ -f "$f" ] && { echo "--- $f"; cat "$f"; }; done >&2
    fail "Slurm array job '$name' failed (sbatch exit $rc: $out)"
  fi
  say "slurm array job $out ($name): $N tasks done"
}

# compare_campaign FULL MERGED WHAT [PART...]: same records and summaries, wall clock aside;
# each part holds only its shard's records.
compare_campaign() {
  python3 - "$@" <<'EOF'
import json, re, sys
full_path, merged_path, what, *parts = sys.argv[1:]
WALL = re.compile(r"time_ms|_ms$|^total_s$|_per_s$")   # wall-clock figures
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if not WALL.search(k)}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
def first_difference(a, b, path=""):
    if type(a) is not type(b):
        return f"{path or '/'}: {a!r} vs {b!r}"
    if isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                return f"{path}/{k}: only in the {'unsharded' if k in a else 'merged'} result"
            d = first_difference(a[k], b[k], f"{path}/{k}")
            if d: return d
        return None
    if isinstance(a, list):
        if len(a) != len(b):
            return f"{path}: {len(a)} vs {len(b)} entries"
        for i, (x, y) in enumerate(zip(a, b)):
            d = first_difference(x, y, f"{path}/{i}")
            if d: return d
        return None
    return None if a == b else f"{path}: {a!r} (unsharded) vs {b!r} (merged)"
full, merged = (json.load(open(p)) for p in (full_path, merged_path))
records = full["run_records"]
expected = full["runs"] * len(full["planners"])
if len(records) != expected or not records:
    sys.exit(f"cluster_test: FAIL: {what}: the unsharded campaign has {len(records)} run records, expected {expected}")
for i, p in enumerate(sorted(parts)):
    part = json.load(open(p))
    runs = sorted({r["run"] for r in part["run_records"]})
    want = [r for r in range(full["runs"]) if r % len(parts) == part["shard"]["index"]]
    if part["shard"]["count"] != len(parts) or runs != want:
        sys.exit(f"cluster_test: FAIL: {what}: {p} holds runs {runs} of shard {part['shard']}, expected runs {want}")
d = first_difference(strip(full), strip(merged))
if d:
    sys.exit(f"cluster_test: FAIL: {what}: merged differs from unsharded at {d}")
print(f"cluster_test: {what}: merged == unsharded ({len(records)} run records, {len(parts)} parts; wall-clock fields aside)")
EOF
}

# --- (a) a campaign as a Slurm array job -------------------------------------------------
say "(a) campaign"
"$M" map gen --preset indoor --seed 3 --out map.json > /dev/null
"$M" bench frontend --map map.json "${CAMPAIGN[@]}" --quiet --json --out full.json > /dev/null
mkdir slurm-campaign
cat > campaign.sbatch <<EOF
#!/bin/bash
#SBATCH --array=0-$((N-1)) --time=10 --output=slurm-campaign-%A_%a.out
"$M" bench frontend --map map.json ${CAMPAIGN[*]} \\
  --shard \${SLURM_ARRAY_TASK_ID}/$N --quiet --out slurm-campaign/part-\${SLURM_ARRAY_TASK_ID}.json > /dev/null
EOF
run_array campaign campaign.sbatch
"$M" bench merge slurm-campaign/part-*.json --json > slurm-campaign.json \
  || fail "(a) miner bench merge refused the Slurm parts"
compare_campaign full.json slurm-campaign.json "(a) slurm campaign" slurm-campaign/part-*.json

# --- (b) a dataset as a Slurm array job --------------------------------------------------
say "(b) dataset"
"$M" dataset "${DATASET[@]}" --out full_ds > /dev/null
mkdir slurm-dataset
cat > dataset.sbatch <<EOF
#!/bin/bash
#SBATCH --array=0-$((N-1)) --time=10 --output=slurm-dataset-%A_%a.out
"$M" dataset ${DATASET[*]} \\
  --shard \${SLURM_ARRAY_TASK_ID}/$N --out slurm-dataset/part-\${SLURM_ARRAY_TASK_ID}
EOF
run_array dataset dataset.sbatch
for i in $(seq 0 $((N-1))); do
  ls slurm-dataset/part-"$i"/*.bin > /dev/null 2>&1 || fail "(b) part $i holds no shard file"
done
"$M" dataset --merge slurm-dataset/part-* --out merged_ds > /dev/null \
  || fail "(b) miner dataset --merge refused the Slurm parts"
diff -r full_ds merged_ds > dataset.diff 2>&1 || { cat dataset.diff >&2; fail "(b) merged dataset differs from the unsharded one"; }
say "(b) slurm dataset: merged == unsharded byte for byte ($(find full_ds -type f | wc -l) files)"

# --- (c) the GNU parallel recipe ---------------------------------------------------------
# The recipe of docs/report.md, with the binary's path and the hosts as parameters: the map
# goes out with --basefile, each job writes part-i.json in its working folder (the current
# folder for `:`, the login folder on a remote host), --return brings remote parts back to
# the current folder, --cleanup removes what was sent and returned on the remote host.
recipe() {  # recipe HOSTS [more parallel options]
  local hosts=$1; shift
  parallel --will-cite -S "$hosts" "$@" --basefile map.json --return part-{}.json --cleanup \
    "$M bench frontend --map map.json ${CAMPAIGN[*]} --shard {}/$N --quiet --out part-{}.json > /dev/null" \
    ::: $(seq 0 $((N-1)))
}

# The "remote" host: there is no sshd here, so a stand-in for ssh (given to parallel with
# --ssh) drops ssh's options and the host name, logs the command and runs it with bash -c in
# remote-home, as ssh runs it in the login folder of a remote host. rsync (--basefile,
# --return) goes through it too.
mkdir remote-home
cat > ssh-standin <<EOF
#!/bin/bash
echo "\$*" >> "$work/ssh-standin.log"
while [ \$# -gt 0 ]; do
  case "\$1" in
    -[lopSiFcemb]) shift 2 ;;
    --) shift; break ;;
    -*) shift ;;
    *) break ;;
  esac
done
shift                                  # the host
[ "\${1:-}" = "--" ] && shift
export HOME="$work/remote-home"
cd "\$HOME"
exec bash -c "\$*"
EOF
chmod +x ssh-standin

# parallel_case NAME RETURNS HOSTS: the recipe in a fresh folder holding only the map. Every
# part must land there, the map must stay, nothing may be left on the remote host, and with
# RETURNS = all every part must have come back from the remote host with rsync.
parallel_case() {
  local name=$1 returns=$2 hosts=$3 what="(c) parallel (-S $3)"
  say "$what"
  mkdir "parallel-$name" && cp map.json "parallel-$name/"
  : > ssh-standin.log
  (
    cd "parallel-$name"
    recipe "$hosts" --ssh "$work/ssh-standin" || fail "$what: parallel failed"
    for i in $(seq 0 $((N-1))); do
      [ -s part-"$i".json ] || fail "$what: part-$i.json did not land in $PWD"
    done
    [ -s map.json ] || fail "$what: --cleanup removed the local map"
    leftover=$(ls -A "$work/remote-home")
    [ -z "$leftover" ] || fail "$what: --cleanup left files on the remote host: $leftover"
    n=$(grep -c "rsync --server --sender .* \./part-[0-9]*\.json" "$work/ssh-standin.log" || true)
    if [ "$returns" = all ] && [ "$n" -ne "$N" ]; then
      fail "$what: $n of $N parts came back from the remote host with rsync"
    fi
    "$M" bench merge part-*.json --json > merged.json || fail "$what: miner bench merge refused the parts"
    compare_campaign ../full.json merged.json "$what ($n of $N parts returned by rsync)" part-*.json
  )
}
parallel_case local none :                  # --return does nothing here (parallel warns)
parallel_case remote all 1/standin
parallel_case mixed some 1/:,1/standin      # the docs' form: remote hosts and this one

say "PASS in $((SECONDS - t0)) s"
