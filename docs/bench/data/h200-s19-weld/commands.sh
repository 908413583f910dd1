# F7: stuck groups simplified over one vertex per position (new) against kept apart (RTR_NO_WELD_STUCK=1,
# d263b98's hierarchy), the 100M and 10M temples, 4K, 1 px, --cull frustum (auto)
source .devz/p.sh x.tar.zst
N=/tmp/w/.device/run.sh; O=/tmp/o; mkdir -p $O
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
T() { local name=$1; shift; echo "== $name ${SECONDS}s"; { echo "# $*"; timeout ${TL:-90} "$@"; echo "# exit $?"; } > $O/$name.txt 2>&1; }
export RTR_PIPELINE_CACHE=/tmp/pc
S=/tmp/s; mkdir -p $S
TL=200 T gen10000 $N scenegen --out $S/m100 --scale 10000
TL=60 T gen1000 $N scenegen --out $S/m10 --scale 1000
for v in weld apart; do e=(); [ $v = apart ] && e=(RTR_NO_WELD_STUCK=1)
  TL=120 T bake100-$v env "${e[@]}" $N rtr-bake $S/m100/temple.obj.zst $S/m100/$v.rtrscene --force --view 0,2.2,-2.5,0,-3
  TL=60 T bake10-$v env "${e[@]}" $N rtr-bake $S/m10/temple.obj.zst $S/m10/$v.rtrscene --force --view 0,2.2,-2.5,0,-3
done
rm -f $S/m100/temple.obj.zst; sync
G="--headless --size 3840x2160 --timings --bench 50 --shading-path visibility --raster compute --lod-error 1 --cull frustum"
V=("stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 0,3,8,0,-15")
for r in 1 2 3; do for v in weld apart; do for s in m100 m10; do for w in "${V[@]}"; do read -r name cam <<<"$w"
  T $s-$v-$name-$r $N rtr-view $S/$s/$v.rtrscene $G $cam; done; done; done; done
echo "took $SECONDS s"
for f in $O/m1*.txt; do printf "%s " $(basename $f .txt); grep -E "^\| (cull|raster|raster large|shade|total) " $f | awk -F'|' '{printf "%s %s ", $2, $3}'; grep -o "[0-9]* triangles listed" $f | tr '\n' ' '; echo; done
grep -h "hierarchy" $O/bake*.txt | grep -v cpu | cut -c1-120
