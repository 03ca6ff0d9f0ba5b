#!/bin/bash
# The logs-at-scale measurement of BENCHMARKS.md: an old and a new build alternated on the
# 10,000-asteroid level (scripts/asteroids_level.py), the small asteroids scenario, diff and
# bench --record. Usage: OLD=path/to/old/ricochet [NEW=target/release/ricochet] [OUT=dir]
#   bash scripts/bench_logs.sh; the figures are in the /usr/bin/time -v outputs in OUT/res.
set -u
OLD=${OLD:?the old build, e.g. a release build of 891484c}
NEW=${NEW:-target/release/ricochet}
L=/tmp/level10k.toml
R=${OUT:-/tmp/ricochet-bench-logs}/res
D=${OUT:-/tmp/ricochet-bench-logs}/logs
mkdir -p $D $R
cd "$(dirname "$0")/.."; NEW=$(realpath "$NEW")
python3 scripts/asteroids_level.py 10000 > $L
python3 scripts/asteroids_level.py 10000 --nudge 0 > /tmp/level10k_ulp.toml
python3 scripts/asteroids_level.py 10000 --seed 13 > /tmp/level10k_s13.toml
t() { local name=$1; shift; /usr/bin/time -v "$@" > $R/$name.out 2> $R/$name.err; echo "rc=$?" >> $R/$name.err; }
for i in 1 2 3; do
  t old10k_$i $OLD run $L -o $D/old10k_$i.mcap
  ls -l $D/old10k_$i.mcap >> $R/sizes.txt
  [ $i -eq 3 ] && rm -f $D/old10k_3.mcap
  t new10k_$i $NEW run $L -o $D/new10k_$i.mcap
  ls -l $D/new10k_$i.mcap >> $R/sizes.txt
  t newbce_$i $NEW run $L -o $D/newbce.mcap --channels bodies,contacts,events
  ls -l $D/newbce.mcap >> $R/sizes.txt
  t newinl_$i env RICOCHET_INLINE_WRITER=1 $NEW run $L -o $D/newinl.mcap
  cmp $D/newinl.mcap $D/new10k_1.mcap >> $R/cmp.txt 2>&1 && echo "inline $i identical" >> $R/cmp.txt
  t newnone_$i $NEW run $L -o $D/newnone.mcap --channels ''
  t oldnone_$i $OLD run $L -o $D/oldnone.mcap --channels ''
done
cmp $D/new10k_1.mcap $D/new10k_2.mcap >> $R/cmp.txt 2>&1 && echo "new runs 1,2 identical" >> $R/cmp.txt
cmp $D/new10k_1.mcap $D/new10k_3.mcap >> $R/cmp.txt 2>&1 && echo "new runs 1,3 identical" >> $R/cmp.txt
for i in 1 2 3 4 5; do
  t oldast_$i $OLD run scenarios/asteroids.toml -o $D/oldast.mcap
  t newast_$i $NEW run scenarios/asteroids.toml -o $D/newast.mcap
done
ls -l $D/oldast.mcap $D/newast.mcap >> $R/sizes.txt
for i in 1 2 3; do t diffnew_$i $NEW diff $D/new10k_1.mcap $D/new10k_2.mcap; done
t newulp $NEW run /tmp/level10k_ulp.toml -o $D/newulp.mcap
t news13 $NEW run /tmp/level10k_s13.toml -o $D/news13.mcap
for i in 1 2 3; do t diffulp_$i $NEW diff $D/new10k_1.mcap $D/newulp.mcap; t diffs13_$i $NEW diff $D/new10k_1.mcap $D/news13.mcap; done
( ulimit -v 8000000; t olddiff timeout 120 $OLD diff $D/old10k_1.mcap $D/old10k_2.mcap )
rm -f $D/old10k_*.mcap
t benchrec $NEW bench --record asteroids-10000 platformer-10000-1000 rain-10000 --frames 600 --keep $D
cp $D/rain-10000.mcap $D/rain-copy.mcap
for i in 1 2 3; do t diffrain_$i $NEW diff $D/rain-10000.mcap $D/rain-copy.mcap; done
echo done > $R/done
