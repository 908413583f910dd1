# F3: the 100M start-up rows after a sync (collect format), the frame, startup and textures groups, the Vulkan suite
source .devz/p.sh b.tar.zst
N=/tmp/w/.device/run.sh; O=/tmp/o; mkdir -p $O/h200 $O/ab
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
row() { local id=$1 t0=$SECONDS; shift; { echo "\$ $*"; $N "$@" 2>&1; echo "# exit $? after $((SECONDS - t0)) s"; } > $O/h200/$id.txt; echo "$id ${SECONDS}s"; }
S=/tmp/s
timeout 200 $N scenegen --out $S/big --scale 10000 >/dev/null 2>&1
timeout 100 $N rtr-bake $S/big/temple.obj.zst $S/big/temple.rtrscene --view 0,2.2,-2.5,0,-3 > $O/ab/bake10000.txt 2>&1
rm -f $S/big/temple.obj.zst; sync
for run in cold warm; do RTR_PIPELINE_CACHE=/tmp/sc row startup-10000-$run rtr-view $S/big/temple.rtrscene --headless --size 3840x2160 --timings --screenshot /tmp/st.png --force; done
for i in 1 2 3; do { RTR_PIPELINE_CACHE=/tmp/sc $N rtr-view $S/big/temple.rtrscene --headless --size 3840x2160 --timings --screenshot /tmp/st.png --force; } > $O/ab/start100m-$i.txt 2>&1; done
rm -rf $S
export RTR_ASSET_DIR=/tmp/w/.device/assets RTR_COMMIT=$(cat .devz/commit)
timeout 330 tools/report/collect.sh $O/c --runner $N --skip gpu,big,compare,env,trace,bake,load,scale
echo "collect done ${SECONDS}s"
left=$((580 - SECONDS)); echo "suite with ${left}s"
if ((left > 90)); then RTR_TEST_LOGS=$O timeout $left /tmp/w/.device/run-tests.sh > $O/vulkan-suite.txt 2>&1; tail -2 $O/vulkan-suite.txt; fi
grep -H "total from\|texture decode\|geometry upload" $O/h200/startup-10000-* $O/ab/start100m-* | cut -c1-150
grep -H "total from" $O/c/startup-* $O/c/textures-bc-* | cut -c1-150
for f in $O/c/frame-default-3840x2160-display*; do printf "%s " $(basename $f); grep -E "^\| total " $f | tr -s ' '; done
