#!/bin/sh
# Bakes meshes with two pleat binaries back to back and compares the OBJ bytes and the times
# (a speed change must give the same bytes with less work). Usage:
#   scripts/lodspeed_compare.sh BASE_BIN NEW_BIN OUT_DIR "SIZES..." mesh1 mesh2 ...
# SIZES are screen sizes n_p; a comma-separated list (`50,100,200`) bakes that chain.
# Prints one line per (mesh, sizes): same/DIFFERENT, wall and user seconds of each binary,
# and the 1-minute load average.
base=$1; new=$2; out=$3; nps=$4; shift 4
mkdir -p "$out"
for m in "$@"; do
  name=$(basename "$m"); name=${name%.*}
  for np in $nps; do
    tag=$(echo "$np" | tr ',' '_')
    for which in base new; do
      bin=$base; [ "$which" = new ] && bin=$new
      /usr/bin/time -f "%e %U" -o "$out/$name.$tag.$which.time" \
        "$bin" lod "$m" --screen-size "$np" -q -o "$out/$name.$tag.$which.{np}.obj" >/dev/null 2>&1
    done
    s=same
    for f in "$out/$name.$tag.base".*.obj; do
      cmp -s "$f" "$(echo "$f" | sed "s/\.$tag\.base\./.$tag.new./")" || s=DIFFERENT
    done
    echo "$name n_p=$np $s base(wall,user)=$(tr '\n' ' ' < "$out/$name.$tag.base.time") new(wall,user)=$(tr '\n' ' ' < "$out/$name.$tag.new.time") load=$(cut -d' ' -f1 /proc/loadavg)"
  done
done
