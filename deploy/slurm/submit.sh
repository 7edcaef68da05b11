#!/usr/bin/env bash
# Processes a sky archive on a Slurm cluster: one array job of DAYS x SHARDS
# tasks (shard.sbatch: `campanile process DAY --shard K/N`), then one job
# that merges each day's shards (merge.sbatch), started only when every
# task has succeeded (afterok). Prints the two job ids.
#
#   deploy/slurm/submit.sh ARCHIVE OUT [--shards N] [--response CSV] [--campanile BIN] [-- sbatch options…]
#
# Example (8 shards a day, the array at most 32 tasks at a time):
#   deploy/slurm/submit.sh /data/sky-station /scratch/sky-out --shards 8 -- --partition=batch
#   squeue -u "$USER"                    # then OUT/DAY/ holds each merged day
#
# ARCHIVE is a station store (one session directory per day, YYYY-MM-DD/);
# OUT gets shards/DAY/K/ (each task's output), DAY/ (the merged day, what an
# unsharded `campanile process DAY --out OUT/DAY` writes) and logs/.
# The binary must be reachable from the compute nodes (an absolute path on
# a shared file system, or `campanile` on their PATH), as must ARCHIVE and OUT.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
usage() { echo "usage: deploy/slurm/submit.sh ARCHIVE OUT [--shards N] [--response CSV] [--campanile BIN] [-- sbatch options…]" >&2; exit 2; }
[ "$#" -ge 2 ] || usage
archive="$(realpath -e "$1")" || { echo "submit.sh: no archive $1" >&2; exit 2; }
out="$(realpath -m "$2")"
shift 2
shards=4
response=""
campanile="campanile"
while [ "$#" -gt 0 ]; do
    case "$1" in
        --shards) shards="${2:?}"; shift 2 ;;
        --response) response="$(realpath -e "${2:?}")" || exit 2; shift 2 ;;
        --campanile) campanile="${2:?}"; shift 2 ;;
        --) shift; break ;;
        *) usage ;;
    esac
done
case "$shards" in ''|*[!0-9]*|0) echo "submit.sh: --shards $shards: expected a whole number >= 1" >&2; exit 2 ;; esac
mapfile -t days < <(find "$archive" -mindepth 1 -maxdepth 1 -type d -name '????-??-??' -printf '%f\n' | sort)
if [ "${#days[@]}" -eq 0 ]; then
    echo "submit.sh: $archive holds no day directory (YYYY-MM-DD/): is it a station store?" >&2
    exit 2
fi
mkdir -p "$out/logs"
vars="ALL,CAMPANILE=$campanile,ARCHIVE=$archive,OUT=$out,SHARDS=$shards,RESPONSE=$response"
tasks=$(( ${#days[@]} * shards ))
array=$(sbatch --parsable "$@" --array="0-$((tasks - 1))" --export="$vars" \
    --output="$out/logs/shard-%a.log" "$here/shard.sbatch")
array="${array%%;*}"
merge=$(sbatch --parsable "$@" --dependency="afterok:$array" --export="$vars" \
    --output="$out/logs/merge.log" "$here/merge.sbatch")
merge="${merge%%;*}"
echo "$array $merge"
echo "submit.sh: ${#days[@]} day(s) x $shards shard(s) = $tasks tasks (job $array), merge job $merge; logs in $out/logs" >&2
