# F9: the final hierarchy (stuck twice: welded over the group's own vertices): the Vulkan suite with validation, then
# the report's scale group (100M bakes, start-up, frames; the 1 B grid)
source .devz/p.sh b.tar.zst
O=/tmp/o; mkdir -p $O
finish() { cp $OUT/gpu.txt $O/ 2>/dev/null; tar cf - -C /tmp o | gzip > $OUT/o.tgz; }; trap finish EXIT
RTR_TEST_LOGS=$O timeout 120 /tmp/w/.device/run-tests.sh > $O/vulkan-suite.txt 2>&1; tail -2 $O/vulkan-suite.txt
echo "suite done ${SECONDS}s"
export RTR_ASSET_DIR=/tmp/w/.device/assets RTR_COMMIT=$(cat .devz/commit)
timeout $((585 - SECONDS)) tools/report/collect.sh $O/h200 --runner /tmp/w/.device/run.sh --skip gpu,frame,big,compare,env,trace,bake,startup,load,textures
echo "took $SECONDS s"
grep -H "total from\|time:" $O/h200/startup-* $O/h200/scale-bake-* | cut -c1-200
for f in $O/h200/scale-frame-*; do printf "%s " $(basename $f); grep -E "^\| total " $f | tr -s ' ' | tr '\n' ' '; grep -o "[0-9]* triangles listed" $f | tr '\n' ' '; echo; done
