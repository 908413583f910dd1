# F5: the 100M bakes without and with the hierarchy after a sync, in collect's row format: nolod, lod, nolod
source .devz/p.sh b.tar.zst
N=/tmp/w/.device/run.sh; O=/tmp/o; mkdir -p $O/ab
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
S=/tmp/s
timeout 200 $N scenegen --out $S/big --scale 10000 >/dev/null 2>&1; sync; echo "gen ${SECONDS}s"
bake() { local id=$1 t0=$SECONDS; shift
  { echo "\$ rtr-bake $S/big/temple.obj.zst $S/big/out.rtrscene --view 0,2.2,-2.5,0,-3 --force $*"
    /usr/bin/time -v $N rtr-bake $S/big/temple.obj.zst $S/big/out.rtrscene --view 0,2.2,-2.5,0,-3 --force "$@" 2>&1; echo "# exit $? after $((SECONDS - t0)) s"
    ls -l $S/big/out.rtrscene; } > $O/ab/$id.txt
  rm -f $S/big/out.rtrscene; sync; grep -o "total [0-9.]* s" $O/ab/$id.txt | tail -1; }
bake scale-bake-10000-nolod-1 --no-lod
bake scale-bake-10000-lod
bake scale-bake-10000-nolod-2 --no-lod
echo "took ${SECONDS}s"
