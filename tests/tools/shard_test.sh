#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# localize --shard I/N and merge (docs/design/experiment.md, "Shards"): three shards
# merged, given in any order, equal the unsharded run in every file (the
# timing columns aside); a missing, repeated or foreign shard (another count,
# seed or map) is refused, and so is a shard.json whose fields do not hold
# what their types, ranges and the shard's index say.
#   shard_test.sh <path to radargauss>
set -u
tool=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
fail() { echo "FAIL: $*"; failed=1; }

"$tool" simulate --out "$work/seq" --scans 40 --seed 6 >/dev/null
"$tool" build-map --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --out "$work/map.rgm" >/dev/null
localize=("$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/map.rgm"
          --w-rcs 0,0.25 --solver gn,ceres --stride 2)
"${localize[@]}" --out "$work/full" >/dev/null
for i in 1 2 3; do "${localize[@]}" --shard "$i/3" --out "$work/s$i" >/dev/null; done
"$tool" merge "$work/s2" "$work/s3" "$work/s1" --out "$work/merged" >/dev/null || fail "merge failed"

for file in reference.tum map_means.csv trajectories/gn-w0-trivial-offset-L3.tum \
            trajectories/ceres-w0.25-trivial-offset-L3.tum; do
  cmp -s "$work/full/$file" "$work/merged/$file" || fail "$file differs"
done
without_time() { rev "$1" | cut -d, -f2- | rev; }
diff <(without_time "$work/full/per_scan.csv") <(without_time "$work/merged/per_scan.csv") >/dev/null ||
  fail "per_scan.csv differs"
diff <(grep -v time_ms "$work/full/summary.json") <(grep -v time_ms "$work/merged/summary.json") >/dev/null ||
  fail "summary.json differs"
without_ms() { awk -F'|' '{ $12 = ""; print }' "$1"; }
diff <(without_ms "$work/full/table.md") <(without_ms "$work/merged/table.md") >/dev/null || fail "table.md differs"
[ "$(wc -l <"$work/merged/per_scan.csv")" -eq 81 ] || fail "merged per_scan.csv has not 4 x 20 rows"

expect_refusal() {
  local needle=$1
  shift
  if "$@" >"$work/out" 2>"$work/err" || ! grep -q -- "$needle" "$work/err"; then
    fail "expected '$needle' from: $*"; cat "$work/err"
  fi
}
expect_refusal "shard 2 of 3 is missing" "$tool" merge "$work/s1" "$work/s3" --out "$work/m2"
expect_refusal "given twice" "$tool" merge "$work/s1" "$work/s1" "$work/s2" "$work/s3" --out "$work/m3"
"${localize[@]}" --shard 1/2 --out "$work/h1" >/dev/null
expect_refusal "another experiment" "$tool" merge "$work/h1" "$work/s2" "$work/s3" --out "$work/m4"
expect_refusal "shard.json" "$tool" merge "$work/seq" --out "$work/m5"
expect_refusal "needs 1 <= I <= N" "${localize[@]}" --shard 4/3 --out "$work/x"
expect_refusal "is not I/N" "${localize[@]}" --shard 1-3 --out "$work/x"
expect_refusal "is empty" "${localize[@]}" --shard 1/30 --out "$work/x"

# Shards know their experiment: another seed, another map.
"${localize[@]}" --seed 9 --shard 2/3 --out "$work/seed9" >/dev/null
expect_refusal "another experiment than $work/s1 ('--seed' is '9'" "$tool" merge "$work/s1" "$work/seed9" "$work/s3" --out "$work/m6"
"$tool" build-map --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --points-per-gaussian 8 \
  --out "$work/other.rgm" >/dev/null
"$tool" localize --sequence "$work/seq" --gt "$work/seq/gt_radar_tum.txt" --map "$work/other.rgm" \
  --w-rcs 0,0.25 --solver gn,ceres --stride 2 --shard 2/3 --out "$work/other_map" >/dev/null
expect_refusal "('maps' is '[0-9]* Gaussians, crc32" "$tool" merge "$work/s1" "$work/other_map" "$work/s3" --out "$work/m7"
[[ ! -e "$work/m6" && ! -e "$work/m7" ]] || fail "a refused merge wrote its folder"

# shard.json read field by field: every fault names the folder and the field.
# mutated <name> <python statement on the dict j>: a copy of shard 2 changed.
mutated() {
  rm -rf "$work/$1" && cp -r "$work/s2" "$work/$1"
  /usr/bin/python3 -c "import json, sys; j = json.load(open(sys.argv[1])); $2; json.dump(j, open(sys.argv[1], 'w'))" \
    "$work/$1/shard.json"
}
while IFS='|' read -r name change needle; do
  mutated "$name" "$change"
  expect_refusal "$needle" "$tool" merge "$work/s1" "$work/$name" "$work/s3" --out "$work/m8"
done <<'CASES'
fewer|j["runs"][0]["outcomes"].pop()|fewer: shard.json: 'runs\[0\].outcomes' must be a list of 7
shifted|j["first_scan"] += 1|are not shard 2 of 3's range of 20 scans
huge|j["of"] = 1e308|huge: shard.json: 'of' must be a whole number in \[0, 1000000\]
typed|j["runs"][1]["outcomes"][0]["converged"] = "yes"|'runs\[1\].outcomes\[0\].converged' must be true or false
unnamed|del j["experiment"]|unnamed: shard.json: 'experiment' is missing
rescanned|j["runs"][0]["outcomes"][1]["scan"] = 3|'runs\[0\].outcomes\[1\].scan' is not the range's scan
CASES
mkdir -p "$work/deep" && /usr/bin/python3 -c "print('[' * 100000)" >"$work/deep/shard.json"
expect_refusal "shard.json: nested deeper than a shard file" "$tool" merge "$work/deep" --out "$work/m8"
mkdir -p "$work/broken" && head -c 100 "$work/s1/shard.json" >"$work/broken/shard.json"
expect_refusal "broken/shard.json: not JSON" "$tool" merge "$work/broken" --out "$work/m8"
if grep -q "json.exception" "$work/err"; then fail "a raw JSON library message"; fi
[[ ! -e "$work/m8" ]] || fail "a refused merge wrote its folder"

[ "$failed" -eq 0 ] && echo "shards: merged equal the unsharded run; 17 refusals"
[ "$failed" -eq 0 ]
