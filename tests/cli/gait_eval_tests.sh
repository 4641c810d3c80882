#!/usr/bin/env bash
# gait-eval on every shipped terrain × gait program must meet the issue's limits
# (foot skate < 0.5 mm, penetration < 1 mm, speed error < 2 %, joint speed
# < 1500 °/s; gait-eval --check exits 1 otherwise). Prints the metrics table.
# Usage: gait_eval_tests.sh MARIONETTE_BINARY SOURCE_DIR
set -uo pipefail
bin=$(realpath "$1")
src=$(realpath "$2")
failures=0
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
# Every pair must meet every limit: nothing is exempt.
printf '%-8s %-14s %9s %9s %9s %9s %6s %7s\n' terrain program skate_mm pen_mm speed_% joint_°/s steps flights
for terrain in flat stairs slope rubble; do
  for program in slow_walk fast_walk run start_stop full_circle reversals stop_mid_step; do
    out=$("$bin" gait-eval --terrain "$terrain" --program "$src/config/programs/$program.prog" --json --check 2>err.txt)
    rc=$?
    field() { sed -E "s/.*\"$1\":([^,}]*).*/\1/" <<<"$out"; }
    printf '%-8s %-14s %9.4f %9.4f %9.4f %9.1f %6s %7s\n' "$terrain" "$program" "$(field foot_skate_mm)" \
      "$(field penetration_mm)" "$(field speed_error_pct)" "$(field max_joint_speed_deg_s)" "$(field steps)" "$(field flight_phases)"
    if [[ $rc -ne 0 ]]; then echo "FAILED: $(cat err.txt)"; failures=$((failures + 1)); fi
    # Walking programs never fly; the run program must.
    if [[ $program == slow_walk || $program == fast_walk ]] && [[ $(field flight_phases) != 0 ]]; then
      echo "FAILED: $terrain $program: a walk has flight phases"; failures=$((failures + 1)); fi
    if [[ $program == run ]] && [[ $(field flight_phases) -lt 10 ]]; then
      echo "FAILED: $terrain $program: running without flight phases"; failures=$((failures + 1)); fi
  done
done
echo "gait-eval: $failures failures"
[[ $failures -eq 0 ]]
