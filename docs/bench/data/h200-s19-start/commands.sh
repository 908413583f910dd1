# F10: 262dea7: the 100M start-up five more times after a sync (collect format), and its frames at 1 px
source .devz/p.sh b.tar.zst
N=/tmp/w/.device/run.sh; O=/tmp/o; mkdir -p $O
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
T() { local name=$1; shift; echo "== $name ${SECONDS}s"; { echo "\$ $*"; timeout ${TL:-90} "$@"; echo "# exit $?"; } > $O/$name.txt 2>&1; }
S=/tmp/s; mkdir -p $S
TL=200 T gen10000 $N scenegen --out $S/big --scale 10000
TL=120 T bake10000 $N rtr-bake $S/big/temple.obj.zst $S/big/temple.rtrscene --view 0,2.2,-2.5,0,-3
rm -f $S/big/temple.obj.zst; sync
for i in 0 1 2 3 4 5; do RTR_PIPELINE_CACHE=$S/cache T startup-10000-$i $N rtr-view $S/big/temple.rtrscene --headless --size 3840x2160 --timings --screenshot /tmp/st.png --force; done
G="--headless --size 3840x2160 --timings --bench 50 --shading-path visibility --raster compute --lod-error 1 --cull frustum"
for r in 1 2; do for w in "stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 0,3,8,0,-15"; do read -r name cam <<<"$w"
  T m100-$name-$r $N rtr-view $S/big/temple.rtrscene $G $cam; done; done
echo "took $SECONDS s"
grep -H "total from\|instance and device\|geometry upload" $O/startup-* | cut -c1-140
for f in $O/m100-*.txt; do printf "%s " $(basename $f .txt); grep -E "^\| total " $f | tr -s ' ' | tr '\n' ' '; echo; done
