# F6: the error's size term, variants by environment (base: longest made edge / 32; aD: the largest made
# triangle's equilateral side / D, at least the longest made edge / (4 D)), 100M and 10M temples, 4K, 1 px
source .devz/p.sh x.tar.zst
N=/tmp/w/.device/run.sh; A=/tmp/w/.device/assets; O=/tmp/o; mkdir -p $O
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
T() { local name=$1; shift; echo "== $name ${SECONDS}s"; { echo "# $*"; timeout ${TL:-90} "$@"; echo "# exit $?"; } > $O/$name.txt 2>&1; }
export RTR_PIPELINE_CACHE=/tmp/pc
S=/tmp/s; mkdir -p $S
TL=200 T gen10000 $N scenegen --out $S/m100 --scale 10000
TL=60 T gen1000 $N scenegen --out $S/m10 --scale 1000
declare -A E=([base]="RTR_SIZE_MODE=0" [a32]="RTR_SIZE_MODE=2 RTR_SIZE_LONG=0.25 RTR_SIZE_DIV=32" [a64]="RTR_SIZE_MODE=2 RTR_SIZE_LONG=0.25 RTR_SIZE_DIV=64")
VS="base a32 a64"
for v in $VS; do
  TL=120 T bake100-$v env ${E[$v]} $N rtr-bake $S/m100/temple.obj.zst $S/m100/$v.rtrscene --force --view 0,2.2,-2.5,0,-3
  TL=60 T bake10-$v env ${E[$v]} $N rtr-bake $S/m10/temple.obj.zst $S/m10/$v.rtrscene --force --view 0,2.2,-2.5,0,-3
done
rm -f $S/m100/temple.obj.zst; sync
G="--headless --size 3840x2160 --bench 50 --shading-path visibility --raster compute --lod-error 1 --cull frustum"
V=("stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 0,3,8,0,-15")
for r in 1 2; do for v in $VS; do for s in m100 $([ $r = 1 ] && echo m10); do for w in "${V[@]}"; do read -r name cam <<<"$w"
  T $s-$v-$name-$r $N rtr-view $S/$s/$v.rtrscene $G $cam; done; done; done; done
echo "took $SECONDS s"
for f in $O/m1*.txt; do printf "%s " $(basename $f .txt); grep -E "^\| (cull|raster|raster large|shade|total) " $f | awk -F'|' '{printf "%s %s ", $2, $3}'; grep -o "[0-9]* triangles listed" $f | tr '\n' ' '; echo; done
grep -h "hierarchy" $O/bake*.txt | cut -c1-200
