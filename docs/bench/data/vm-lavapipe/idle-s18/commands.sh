set -x
B=/work/main/build/release/bin
cd /tmp/tx18
$B/scenegen --out s --textures 200 >/dev/null 2>&1
/usr/bin/time -v $B/rtr-bake s/temple.obj.zst bc/temple.rtrscene --textures bc > bake.txt 2>&1
mkdir -p cache
RTR_TEXTURE_CACHE=off RTR_PIPELINE_CACHE=cache $B/rtr-view bc/temple.rtrscene --headless --size 1920x1080 --timings --wait-textures --screenshot warm.png --force > warm.txt 2>&1
for r in 1 2 3; do uptime; RTR_TEXTURE_CACHE=off RTR_PIPELINE_CACHE=cache /usr/bin/time -v $B/rtr-view bc/temple.rtrscene --headless --size 1920x1080 --timings --wait-textures --screenshot r$r.png --force > r$r.txt 2>&1; done
echo done
B=/work/main/build/release/bin
cd /tmp/tx18
/usr/bin/time -v $B/rtr-bake s/temple.obj.zst files/temple.rtrscene --textures files > bake-files.txt 2>&1
for r in 1 2 3; do uptime; RTR_TEXTURE_CACHE=off RTR_PIPELINE_CACHE=cache $B/rtr-view files/temple.rtrscene --headless --size 1920x1080 --timings --wait-textures --screenshot f$r.png --force > f$r.txt 2>&1; done
rm -rf tcache
for r in 1 2; do
 rm -rf tcache; uptime
 RTR_TEXTURE_CACHE=tcache RTR_PIPELINE_CACHE=cache $B/rtr-view s/temple.obj.zst --headless --size 1920x1080 --timings --wait-textures --screenshot d1.png --force > d1-$r.txt 2>&1
 RTR_TEXTURE_CACHE=tcache RTR_PIPELINE_CACHE=cache $B/rtr-view s/temple.obj.zst --headless --size 1920x1080 --timings --wait-textures --screenshot d2.png --force > d2-$r.txt 2>&1
done
echo done
