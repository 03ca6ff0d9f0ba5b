#!/bin/bash
# A golden-log suite as a Slurm job array: array task K of N runs the K-th of N shards of
# the suite, `ricochet test --shard K/N`. The N shards together run every scenario once.
#
#   sbatch docs/examples/slurm-golden.sh            # from the game's repository
#   sbatch --array=0-15 docs/examples/slurm-golden.sh  # 16 shards: N follows the array
#
# Each task prints its verdict lines and its `N passed, M failed` to its own output file
# and writes its own JUnit report; a task exits 1 when a scenario of its shard fails, so
# `sacct -j JOBID` shows which shards failed. `ricochet` must be on the PATH of the nodes
# (or set RICOCHET to its path), and the repository on a filesystem they share.
#
#SBATCH --job-name=ricochet-golden
#SBATCH --array=0-3
#SBATCH --cpus-per-task=2
#SBATCH --mem-per-cpu=1G
#SBATCH --time=00:30:00
#SBATCH --output=golden-%A_%a.out

set -euo pipefail

: "${SLURM_ARRAY_TASK_ID:?submit this script with sbatch (it is a job array task)}"
# The number of tasks in the array (0-3: 4). The shards must be numbered 0 to N-1, as
# `--array=0-N-1` numbers the tasks.
shards="${SLURM_ARRAY_TASK_COUNT:?Slurm sets this for a job array}"

cd "${SLURM_SUBMIT_DIR:-.}"
mkdir -p reports
"${RICOCHET:-ricochet}" test scenarios --golden recordings \
    -j "${SLURM_CPUS_PER_TASK:-1}" \
    --shard "${SLURM_ARRAY_TASK_ID}/${shards}" \
    --junit "reports/golden-${SLURM_ARRAY_TASK_ID}.xml"
