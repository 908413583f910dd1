# Session 19 (2026-11-27), this 2-core VM: why the 100M temple's cut is denser than the 10M's.
# The variants were environment switches in src/scene/cluster_lod.cpp for the experiment only (not in the
# code now); each file's hierarchy was built by `rtr-lod-cut --rebuild` from a scene baked with --no-lod:
#   scenegen --scale S --out sS; rtr-bake sS/temple.obj.zst sS/n.rtrscene --no-lod --view 0,2.2,-2.5,0,-3
#   rtr-lod-cut sS/n.rtrscene --rebuild --size 3840x2160 --lod-error 1 > lodcut-rebuild-V-sS.txt
# V:
#   base  d263b98 (size term: longest made edge / 32)
#   x     groups grown by the neighbour whose error sphere grows the group's least (not the one sharing most
#         edges): compact groups, but levels stop halving from level 5 (stuck); not adopted
#   s1    size term from the made triangles' mean area (side of the equilateral triangle of that area / 32)
#   s2    size term from the largest made triangle's area (same side / 32)
#   s3    s2, at least the longest made edge / 128 (the H200 runs' "a32"; a64: / 64 and / 256)
#   w     base + stuck groups simplified again over one vertex per position, the mesh's first vertex there
#         (dbbf04d; replaced: it shaded the 2CylinderEngine's fins with other faces' normals)
#   final the code since: groups stuck a second time, over the group's own first vertex at each position
# floor-sS.txt: base, --mesh floor. Radius diagnostic (not in a file): projecting every error at the
# sphere's centre (radius x 0) changed the cut by -4 % (10M) and -5 % (30M): the spheres' growth is not it.
# image-1m-1080p-V.txt (V also final): tools/bench_cull/lod.sh with SCALES=100 SIZES=1920x1080 LODS="0 1 4" FRAMES=3 on
# lavapipe, the bake's hierarchy built with variant V (base, a32, a64, a128).
