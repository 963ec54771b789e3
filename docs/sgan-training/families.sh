#!/usr/bin/env bash
# The recipe of the shipped weights (fixtures/sgan) and of the leave-one-family-out ones
# (fixtures/sgan/lofo), session 13. Data here (2 cores: ~17 min, scan alone 8.5 min); training
# on one H100, all eight runs at once (~6 min).
#   bash docs/sgan-training/families.sh data    [miner]   -> fam-*/ (train, val, 40 test maps each)
#   bash docs/sgan-training/families.sh train   [cuda]    -> runs/all, runs/without-F (sgan-0.1.bin: shipped)
#   bash docs/sgan-training/families.sh cube    [cuda]    -> the same with the cube's 48 symmetries
#        (--augment 2) and a width-4 network beside them: session 18's experiment, not shipped
#        (docs/heuristic.md); one H200, all nine runs at once, 421 s
#   bash docs/sgan-training/families.sh longer  [cuda]    -> runs-longer/all (20 epochs), runs-longer/without-F
#        (12 epochs): the shipped recipe trained longer, session 20's experiment, not shipped
#        (docs/heuristic.md); one H200, all eight runs at once, 490 s
#   bash docs/sgan-training/families.sh grid16  [cuda]    -> runs-grid16/all, runs-grid16/without-F: the 16^3
#        network (train.py --pool 2, fixtures/sgan/grid16 at threshold 0.2); one H200, all eight
#        runs at once, 178 s (session 19)
#   bash docs/sgan-training/families.sh passability [cuda] -> runs-pass/all, runs-pass/without-F: the shipped
#        recipe with the network reading channel P (dataset v2; session 24)
#   bash docs/sgan-training/families.sh data-mixed [miner] -> fam-mixed/, then
#   bash docs/sgan-training/families.sh mixed  [cuda]    -> runs-mixed/all, runs-mixed/without-F: the
#        passability recipe with the `mixed` family in every run (domain randomisation; session 25)
set -euo pipefail
families=(sim indoor cluttered rooms forest multilevel scan)
declare -A count=([sim]=2000 [indoor]=1200 [cluttered]=2000 [rooms]=2000 [forest]=2000 [multilevel]=1500 [scan]=700)
here=$(cd "$(dirname "$0")/../.." && pwd)
# The recipes before session 24 trained networks without channel P; train.py now reads it by
# default (--passability-channels 3), so they say so (their recorded commands gain the option).
no_p="--passability-channels 0"
all=(); for f in "${families[@]}"; do all+=("fam-$f"); done
# train_bg OUT LOG WIDTH EPOCHS OPTIONS DATA...: one train.py run in the background; OPTIONS (may
# be empty) go after --width, e.g. "--augment 2" or "--pool 2"; threads=N before the call sets
# --threads (default 1). The options keep one order: train.py records its command in the weights.
train_bg() {
  local out=$1 log=$2 width=$3 epochs=$4 options=$5
  shift 5
  # shellcheck disable=SC2086  # OPTIONS are words
  python3 "$here/src/python/sgan/train.py" --data "$@" --device "$device" --threads "${threads:-1}" --width "$width" \
    $options --epochs "$epochs" --val-samples 280 --out "$out" > "$log" &
}
# lofo_bg PREFIX OPTIONS [EPOCHS]: the seven leave-one-family-out runs (width 8, 8 epochs).
lofo_bg() {
  local held f rest
  for held in "${families[@]}"; do
    rest=(); for f in "${families[@]}"; do [ "$f" != "$held" ] && rest+=("fam-$f"); done
    train_bg "$1/without-$held" "$1-without-$held.log" 8 "${3:-8}" "$2" "${rest[@]}"
  done
}
# set_threshold T REASON RUN...: RUN/sgan-T.bin, each RUN's weights with threshold T.
set_threshold() {
  local t=$1 reason=$2 r
  shift 2
  for r in "$@"; do
    python3 "$here/src/python/sgan/set_threshold.py" --weights "$r/sgan.bin" --threshold "$t" --reason "$reason" \
      --out "$r/sgan-$t.bin"
  done
}
case "${1:-}" in
  data)
    miner=${2:-build/release/miner}
    for f in "${families[@]}"; do
      "$miner" dataset --preset "$f" --count "${count[$f]}" --test-count 40 --seed 11 --jobs 2 --quiet --out "fam-$f"
    done ;;
  train)
    device=${2:-cuda}
    train_bg runs/all runs-all.log 8 16 "$no_p" "${all[@]}"
    lofo_bg runs "$no_p"
    wait
    # The threshold, chosen on the validation split by the strict rates (docs/heuristic.md):
    set_threshold 0.1 "chosen on the validation split by strict connectivity + safety" runs/all runs/without-* ;;
  cube)
    device=${2:-cuda}
    for w in 8 4; do train_bg "runs-cube/all-w$w" "runs-cube-all-w$w.log" "$w" 16 "--augment 2 $no_p" "${all[@]}"; done
    lofo_bg runs-cube "--augment 2 $no_p"
    wait ;;
  longer)
    device=${2:-cuda}
    threads=3 train_bg runs-longer/all runs-longer-all.log 8 20 "$no_p" "${all[@]}"
    lofo_bg runs-longer "$no_p" 12
    wait
    set_threshold 0.1 "as the shipped threshold" runs-longer/all runs-longer/without-* ;;
  grid16)
    device=${2:-cuda}
    threads=2 train_bg runs-grid16/all runs-grid16-all.log 8 16 "--pool 2 $no_p" "${all[@]}"
    lofo_bg runs-grid16 "--pool 2 $no_p"
    wait
    # The threshold, chosen on held-back 16^3 maps (dataset seed 2000003) by strict connectivity
    # + safety (docs/figures/threshold_sweep.sh with SPLIT=test PREFIX=s16-; docs/heuristic.md):
    set_threshold 0.2 "chosen on held-back 16^3 maps (seed 2000003) by strict connectivity + safety" \
      runs-grid16/all runs-grid16/without-* ;;
  passability)
    # Session 24: the shipped recipe (all families 16 epochs, leave-one-out 8) on dataset v2,
    # the network reading channel P (train.py's default --passability-channels 3); the data of
    # `data` above with the same seeds, so E, S and T are the shipped network's and only P is new.
    device=${2:-cuda}
    train_bg runs-pass/all runs-pass-all.log 8 16 "" "${all[@]}"
    train_bg runs-pass/all-e20 runs-pass-all-e20.log 8 20 "" "${all[@]}"  # session 20's longer recipe
    lofo_bg runs-pass ""
    wait ;;
  data-mixed)
    # Session 25: the `mixed` family (REQ-WORLD-020), the other families' parts at random, with
    # the seeds of `data` (2 cores: 4.7 min).
    miner=${2:-build/release/miner}
    "$miner" dataset --preset mixed --count 2000 --test-count 40 --seed 11 --jobs 2 --quiet --out fam-mixed ;;
  mixed)
    # Session 25: domain randomisation. The passability recipe with fam-mixed (`data-mixed`)
    # added to every run: all eight families 16 epochs, and each of the seven named families held
    # out in turn (8 epochs), so the leave-one-out networks still never see the family they are
    # measured on. Each run writes a checkpoint after every epoch (a run cut short by a time
    # limit is exported from it with --resume and --epochs of the epochs done).
    device=${2:-cuda}
    mkdir -p ckpt-mixed
    train_bg runs-mixed/all runs-mixed-all.log 8 16 "--checkpoint ckpt-mixed/all.pt" "${all[@]}" fam-mixed
    for held in "${families[@]}"; do
      rest=(); for f in "${families[@]}"; do [ "$f" != "$held" ] && rest+=("fam-$f"); done
      train_bg "runs-mixed/without-$held" "runs-mixed-without-$held.log" 8 8 "--checkpoint ckpt-mixed/without-$held.pt" \
        "${rest[@]}" fam-mixed
    done
    wait ;;
  *) echo "usage: $0 data [miner] | data-mixed [miner] | train [cuda] | cube [cuda] | longer [cuda] | grid16 [cuda] | passability [cuda] | mixed [cuda]" >&2
     exit 2 ;;
esac
