# F2a: the 100M start-up with the hierarchy, records built in pieces (new) against 3d54abe (main); the clear in shading A/B
source .devz/p.sh b.tar.zst main.tar.zst
N=/tmp/w/.device/run.sh; M=/tmp/w/main/run.sh; A=/tmp/w/.device/assets; O=/tmp/o; mkdir -p $O/ab
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
T() { local name=$1; shift; echo "== $name ${SECONDS}s"; { echo "# $*"; timeout ${TL:-90} "$@"; echo "# exit $?"; } > $O/ab/$name.txt 2>&1; }
export RTR_PIPELINE_CACHE=/tmp/pc
F="--headless --size 3840x2160 --timings"
for r in 1 2; do for v in "stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 0,3,8,0,-15"; do read -r name cam <<<"$v"
  for c in 1 0; do T temple-clear$c-$name-$r env RTR_CLEAR_IN_SHADE=$c $N rtr-view $A/temple.rtrscene $F --bench 100 $cam; done
  T temple-main-$name-$r $M rtr-view $A/temple.rtrscene $F --bench 100 $cam
done; done
S=/tmp/s; mkdir -p $S
TL=200 T gen10000 $N scenegen --out $S/m100 --scale 10000
TL=100 T bake10000 $N rtr-bake $S/m100/temple.obj.zst $S/m100/temple.rtrscene --view 0,2.2,-2.5,0,-3
rm -f $S/m100/temple.obj.zst; sync; echo 3 > /proc/sys/vm/drop_caches; cat $S/m100/temple.rtrscene > /dev/null
T upload-e-100m-new $N rtr-bench-upload --only e --scene $S/m100/temple.rtrscene --reps 3
T upload-e-100m-old $M rtr-bench-upload --only e --scene $S/m100/temple.rtrscene --reps 3
for i in 1 2 3; do T start100m-new-$i $N rtr-view $S/m100/temple.rtrscene $F --screenshot /tmp/s.png --force; T start100m-main-$i $M rtr-view $S/m100/temple.rtrscene $F --screenshot /tmp/s.png --force; done
echo "took $SECONDS s"
for f in $O/ab/temple-*.txt; do printf "%s " $(basename $f .txt); grep -E "^\| (clear|shade|total) " $f | tr -s ' ' | tr '\n' ' '; echo; done
grep -H "longest build\|streams\|direct" $O/ab/upload-e-* | cut -c1-220
grep -H "total from\|geometry upload\|scene file read\|waiting for the scene" $O/ab/start100m-* | cut -c1-160
