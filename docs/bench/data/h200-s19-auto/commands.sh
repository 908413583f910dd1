# F11: 262dea7: --cull on against frustum for grids of N instances of the 10M temple (auto's rule), 4K, 1 px
source .devz/p.sh b.tar.zst
N=/tmp/w/.device/run.sh; O=/tmp/o11; mkdir -p $O
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o11 | gzip > $OUT/o.tgz; }; trap finish EXIT
T() { local name=$1; shift; echo "== $name ${SECONDS}s"; { echo "\$ $*"; timeout ${TL:-90} "$@"; echo "# exit $?"; } > $O/$name.txt 2>&1; }
G="--headless --size 3840x2160 --timings --bench 50 --shading-path visibility --raster compute --lod-error 1"
for n in 1 2 4 9 16 36; do
  rm -rf /tmp/g; TL=120 T gen-$n $N scenegen --out /tmp/g --scale 1000 --instances $n
  f=/tmp/g/temple-grid.rtrscene
  for w in "stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 16.34,17.74,16.06,30,-25"; do read -r name cam <<<"$w"
    for c in on frustum; do T g$n-$name-$c $N rtr-view $f $G --cull $c $cam; done; done
done
echo "took $SECONDS s"
for f in $O/g*.txt; do printf "%s " $(basename $f .txt); grep -E "^\| total " $f | tr -s ' ' | tr '\n' ' '; grep -o "[0-9]* triangles listed" $f | tr '\n' ' '; echo; done
