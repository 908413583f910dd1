# F4: the 100M bake without the hierarchy after a sync, three times (collect's row format); the default temple's display rows again
source .devz/p.sh b.tar.zst
N=/tmp/w/.device/run.sh; O=/tmp/o; mkdir -p $O/ab; A=/tmp/w/.device/assets
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
S=/tmp/s
timeout 200 $N scenegen --out $S/big --scale 10000 >/dev/null 2>&1; sync; echo "gen ${SECONDS}s"
for r in 1 2 3; do t0=$SECONDS
  { echo "\$ rtr-bake $S/big/temple.obj.zst $S/big/nolod.rtrscene --no-lod --view 0,2.2,-2.5,0,-3 --force"
    /usr/bin/time -v $N rtr-bake $S/big/temple.obj.zst $S/big/nolod.rtrscene --no-lod --view 0,2.2,-2.5,0,-3 --force 2>&1; echo "# exit $? after $((SECONDS - t0)) s"
    ls -l $S/big/nolod.rtrscene; } > $O/ab/scale-bake-10000-nolod-$r.txt
  rm -f $S/big/nolod.rtrscene; sync; grep "time:" $O/ab/scale-bake-10000-nolod-$r.txt | cut -c1-220
done
for r in 1 2 3; do for v in "display" "display-inside --camera 0,1.5,0,30,-5" "display-outside --camera 0,3,8,0,-15"; do read -r name cam <<<"$v"
  { echo "\$ rtr-view $A/temple.rtrscene --headless --size 3840x2160 --bench 100 --timings $cam"; $N rtr-view $A/temple.rtrscene --headless --size 3840x2160 --bench 100 --timings $cam 2>&1; } > $O/ab/frame-$name-$r.txt
  printf "%s-%s " $name $r; grep -E "^\| total " $O/ab/frame-$name-$r.txt | tr -s ' '
done; done
echo "took ${SECONDS}s"
