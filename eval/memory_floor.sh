#!/usr/bin/env bash
# The cost floor of the default pipeline's memory traffic, beside the real passes, in one run.
#
# Builds a throw-away copy of the working tree in which temporal.comp and stereo.comp keep only
# what the default pipeline cannot do without: per pixel, the temporal pass fetches the current
# pixel, reprojects and takes one bilinear tap of the history, and stores the new history
# (RGBA16F); the stereo pass fetches this eye's history, reprojects and takes one bilinear tap of
# the other eye, and stores the output. No 3x3 window, no clip, no weights: if this skeleton is
# already near the copy-ratio target, no tuning of the arithmetic can meet it.
#
# Usage: eval/memory_floor.sh [steadyxr-bench arguments]   (default: the three bench sizes)
# Prints the bench table of the skeleton (its `hybrid`, `stereo` and `default` rows are the
# skeleton passes) and, from the same script, the real passes built from the unmodified tree.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

git -C "$root" ls-files -z | (cd "$root" && tar --null -T - -cf -) | tar -xf - -C "$work"

python3 - "$work/shaders" <<'EOF'
import pathlib, sys
shaders = pathlib.Path(sys.argv[1])
main = '''
void main() {
  ivec2 base = ivec2(gl_GlobalInvocationID.xy) * ivec2(kBlockW, kBlockH);
  if (any(greaterThanEqual(base, P.src0Rect.zw))) return;
  PROCESS_BLOCK(base);
}
'''
def skeleton(alpha, stores):
    # fetch this pixel, one reprojected bilinear tap of src1, blend, store
    return f'''void processPixel(ivec2 p, ivec2 o) {{
  const bool inRange = all(lessThan(p, P.src0Rect.zw));
  vec3 cur = fetchSrc0(p);
  vec2 q;
  float iz;
  bool inside = reproject(P.reproj[0], vec2(p) + 0.5, P.w1.w, q, iz);
  vec3 result = inside ? mix(sampleSrc1(q), cur, {alpha}) : cur;
  if (inRange) {{
{stores}
  }}
}}
'''
skeletons = {
    'temporal.comp': skeleton('0.1', '    if (kWriteHist) imageStore(uHistOut, p, vec4(result, 1.0));\n'
                                     '    if (kWriteOut) writeOutput(p, result);'),
    'stereo.comp': skeleton('0.5', '    writeOutput(p, result);'),
}
for name, body in skeletons.items():
    path = shaders / name
    text = path.read_text()
    cut = text.index('void processPixel(')  # everything from here on is replaced
    path.write_text(text[:cut] + body + main)
EOF

bench_args=("$@")
if ((${#bench_args[@]} == 0)); then bench_args=(--iterations 5 --warmup 2); fi
methods=(--methods hybrid,stereo,default)
for tree in "$work" "$root"; do
  cmake -S "$tree" -B "$tree/build-floor" -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build "$tree/build-floor" -j"$(nproc)" --target steadyxr-bench >/dev/null
done
echo "== skeleton: only the fetches, bilinear taps and stores the default pipeline needs"
"$work/build-floor/layer/core/bench/steadyxr-bench" "${methods[@]}" "${bench_args[@]}" | grep '^|'
echo "== the real passes, same build settings"
"$root/build-floor/layer/core/bench/steadyxr-bench" "${methods[@]}" "${bench_args[@]}" | grep '^|'
