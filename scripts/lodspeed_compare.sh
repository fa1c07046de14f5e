#!/bin/sh
# Bakes meshes with two pleat binaries back to back and compares the OBJ bytes and the times
# (issue 12 part 2, "same bytes, less work"). Usage:
#   scripts/lodspeed_compare.sh BASE_BIN NEW_BIN OUT_DIR "np1 np2" mesh1 mesh2 ...
# Prints one line per (mesh, n_p): same/DIFFERENT, wall and user seconds of each binary.
base=$1; new=$2; out=$3; nps=$4; shift 4
mkdir -p "$out"
for m in "$@"; do
  name=$(basename "$m"); name=${name%.*}
  for np in $nps; do
    for which in base new; do
      bin=$base; [ "$which" = new ] && bin=$new
      /usr/bin/time -f "%e %U" -o "$out/$name.$np.$which.time" \
        "$bin" lod "$m" --screen-size "$np" -q -o "$out/$name.$np.$which.obj" >/dev/null 2>&1
    done
    if cmp -s "$out/$name.$np.base.obj" "$out/$name.$np.new.obj"; then s=same; else s=DIFFERENT; fi
    echo "$name n_p=$np $s base(wall,user)=$(cat "$out/$name.$np.base.time" | tr '\n' ' ') new(wall,user)=$(cat "$out/$name.$np.new.time" | tr '\n' ' ') load=$(cut -d' ' -f1 /proc/loadavg)"
  done
done
