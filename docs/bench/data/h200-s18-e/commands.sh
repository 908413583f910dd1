# E: --cull off / frustum / on at 1 px: the default temple, the 100M temple, three views each (main at 8a9d2c9)
source .devz/p.sh e.tar.zst
N=/tmp/w/.device/run.sh; A=/tmp/w/.device/assets; O=/tmp/o; mkdir -p $O
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
T() { local name=$1; shift; { echo "# $*"; timeout ${TL:-90} "$@"; echo "# exit $?"; } > $O/$name.txt 2>&1; }
export RTR_PIPELINE_CACHE=/tmp/pc
F="--headless --size 3840x2160 --timings"
V=("stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 0,3,8,0,-15")
for r in 1 2; do for v in "${V[@]}"; do read -r name cam <<<"$v"; for c in off frustum on; do
  T temple-$c-$name-$r $N rtr-view $A/temple.rtrscene $F --bench 100 --cull $c $cam; done; done; done
S=/tmp/s; mkdir -p $S
TL=200 T gen10000 $N scenegen --out $S/m100 --scale 10000
TL=100 T bake10000 $N rtr-bake $S/m100/temple.obj.zst $S/m100/temple.rtrscene --view 0,2.2,-2.5,0,-3
rm -f $S/m100/temple.obj.zst
G="$F --bench 50 --shading-path visibility --raster compute --lod-error 1"
for r in 1 2; do for v in "${V[@]}"; do read -r name cam <<<"$v"; for c in off frustum on; do
  T m100-$c-$name-$r $N rtr-view $S/m100/temple.rtrscene $G --cull $c $cam; done; done; done
echo "took $SECONDS s"
for f in $O/temple-*.txt $O/m100-*.txt; do printf "%s " $(basename $f .txt); grep -E "^\| (cull|total) " $f | tr -s ' ' | tr '\n' ' '; grep -o "[0-9]* triangles listed" $f | tr '\n' ' '; echo; done
