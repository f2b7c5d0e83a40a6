#!/usr/bin/env bash
# Submits a counterpoise study to Slurm: a job array of N shards and a merge job that starts
# when every shard has succeeded.
#
#   scripts/slurm/submit.sh CASE N DIR [run options…]
#
# DIR must be on a file system every node sees: the shards write DIR/shards/shard-I-of-N.json,
# the merge writes DIR/results.json and the reports, the jobs' output goes to DIR/logs. Run
# options (--dmax, --minimax, --resolution, --tolerance) go to every shard; the merge reads
# them from the shard files. SBATCH_OPTIONS adds sbatch options to both jobs (e.g.
# "--partition=long --cpus-per-task=8 --time=4:00:00"); COUNTERPOISE names the binary.
# Prints the two job ids, then `array=ID merge=ID` on the last line.
set -euo pipefail
if [[ $# -lt 3 ]]; then
    echo "usage: $0 CASE N DIR [run options…]" >&2
    exit 2
fi
case_file=$1 shards=$2 dir=$3
shift 3
if ! [[ $shards =~ ^[1-9][0-9]*$ ]]; then
    echo "error: N must be a whole number ≥ 1, not \`$shards\`" >&2
    exit 2
fi
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$dir/logs"
read -r -a extra <<< "${SBATCH_OPTIONS:-}"
array=$(sbatch --parsable "${extra[@]}" --array="1-$shards" \
    --output="$dir/logs/%x-%A_%a.out" \
    "$here/study.sbatch" "$case_file" "$shards" "$dir" "$@")
array=${array%%;*}
merge=$(sbatch --parsable "${extra[@]}" --dependency="afterok:$array" --kill-on-invalid-dep=yes \
    --output="$dir/logs/%x-%j.out" \
    "$here/merge.sbatch" "$dir")
merge=${merge%%;*}
echo "submitted the shards 1-$shards as array job $array and the merge as job $merge"
echo "array=$array merge=$merge"
