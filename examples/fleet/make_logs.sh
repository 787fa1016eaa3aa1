#!/usr/bin/env bash
# The logs of the trend walkthrough (docs/trend.md): two 2.2 kW motors, one 6 s log a day
# (2 kHz, a direct-on-line start) for 14 days from 2026-11-01. pump_1 is healthy; pump_2's
# connection loosens, its stator resistance 2.5 % up a day (+32.5 % on day 14), there
# from each log's first sample. Usage, from the repository's root:
#   bash examples/fleet/make_logs.sh fleet_logs            # about 10 s
#   sim-host fleet examples/fleet/motors.toml fleet_logs/*.csv --store history.db
#   sim-host trend --store history.db
# SIM names the binary (default: sim-host on the PATH).
set -euo pipefail
sim=${SIM:-sim-host}
out=${1:-fleet_logs}
mkdir -p "$out"
scenario=$(mktemp)
trap 'rm -f "$scenario"' EXIT
for day in $(seq 1 14); do
  date=$(printf '202611%02d' "$day")
  for motor in pump_1 pump_2; do
    change=0.0
    if [ "$motor" = pump_2 ]; then
      change=$(awk -v d="$day" 'BEGIN { printf "%.3f", 0.025 * (d - 1) }')
    fi
    printf 'duration_s = 6.0\nsample_rate_hz = 2000.0\nseed = %d\n[[faults]]\nkind = "rs"\nat_s = 0.0\nchange = %s\n' \
      "$day" "$change" > "$scenario"
    "$sim" simulate --params examples/params/2p2kw.toml --scenario "$scenario" \
      --out "$out/${motor}_${date}_0600.csv" > /dev/null
  done
done
echo "wrote 28 logs to $out"
