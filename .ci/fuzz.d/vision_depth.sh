# Depth front end readers (tests/fuzz/vision/depth_fuzz.cpp): first byte 0 PNG (then the cloud),
# 1 frame list, 2 intrinsics, 3 camera pose, 4 region. Built only when tests/fuzz/CMakeLists.txt
# includes tests/fuzz/vision/depth.cmake. Seeds: a 4x3 16-bit PNG, the same cut short, a TUM list,
# a `pliant record` depth_frames.csv, and one valid and one malformed text of each kind.
if cmake --build "$build" --target help 2>/dev/null | grep 'vision_depth_fuzz' >/dev/null; then
  cmake --build "$build" --target vision_depth_fuzz -j "$(nproc)"
  depth_fuzzer="$build/bin/vision_depth_fuzz"
  [ -x "$depth_fuzzer" ] || depth_fuzzer="$(find "$build" -type f -name vision_depth_fuzz -perm -u+x | head -n 1)"
  depth_corpus="$build/fuzz/vision-depth-corpus"
  depth_artifacts="$build/fuzz/vision-depth-artifacts"
  mkdir -p "$depth_corpus" "$depth_artifacts"
  depth_png='\211\120\116\107\015\012\032\012\000\000\000\015\111\110\104\122\000\000\000\004\000\000\000\003\020\000\000\000\000\301\017\055\131\000\000\000\044\111\104\101\124\170\332\143\140\140\140\140\147\340\143\020\145\140\176\301\374\236\371\033\363\137\006\366\013\354\327\331\357\261\077\005\000\103\003\007\207\105\213\230\257\000\000\000\000\111\105\116\104\256\102\140\202'
  printf "\\000$depth_png" > "$depth_corpus/seed-png"
  head -c 60 "$depth_corpus/seed-png" > "$depth_corpus/seed-png-cut"
  printf '\001# depth maps\n1305031102.160407 depth/1305031102.160407.png\r\n1305031102.194330\tdepth/2.png\n' \
    > "$depth_corpus/seed-list"
  printf '\0012 a.png\n1 b.png\n' > "$depth_corpus/seed-list-bad"
  printf '\001index,t,file,depth_scale_m,fx,fy,cx,cy\n0,0.0334,depth/000000.png,0.001,570.3,570.3,319.5,239.5\r\n1,0.0667,depth/000001.png,0.001,nan,nan,nan,nan\n' \
    > "$depth_corpus/seed-recorded-list"
  printf '\001index,t,file,depth_scale_m,fx,fy,cx,cy\n0,0.1,a.png,-1,1,1,1\n' > "$depth_corpus/seed-recorded-list-bad"
  printf '\002517.3,516.5,318.6,255.3' > "$depth_corpus/seed-intrinsics"
  printf '\0020,1,2' > "$depth_corpus/seed-intrinsics-bad"
  printf '\0030.1,0.2,0.3,0,0,0.7071068,0.7071068' > "$depth_corpus/seed-pose"
  printf '\0030,0,0,0,0,0,2' > "$depth_corpus/seed-pose-bad"
  printf '\00410,20,30,40' > "$depth_corpus/seed-region"
  printf '\0041.5,0,1,1' > "$depth_corpus/seed-region-bad"

  fuzz_run "$depth_fuzzer" "$depth_corpus" \
    -max_total_time="${PLIANT_DEPTH_FUZZ_SECONDS:-10}" \
    -max_len=4096 \
    -timeout=10 \
    -rss_limit_mb=2048 \
    -artifact_prefix="$depth_artifacts/" \
    -print_final_stats=1
else
  echo "vision_depth_fuzz: not in this build (tests/fuzz/CMakeLists.txt does not include vision/depth.cmake); skipped"
fi
