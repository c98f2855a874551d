#!/bin/bash -eu
# ClusterFuzzLite's build step: every warpcheck fuzz target into $OUT (fuzz/oss-fuzz/build.sh says how).
"$SRC/warpcheck/fuzz/oss-fuzz/build.sh"
