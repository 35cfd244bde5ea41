#!/usr/bin/env bash
# erodem — packs what gpu_check.sh runs for a machine that has a GPU and its driver but none of
# erodem's packages (docs/performance.md, "Results": the H200 and H100 runs), and unpacks it
# there.
#
#   bash experiments/benchmarks/gpu_bundle.sh pack BUILD_DIR OUT_DIR
#     writes OUT_DIR/bundle.tar.xz: BUILD_DIR's cli/erodem and tests/erodem_tests, every shared
#     library they load except the C library's own (glibc is the target's: it must be as new
#     as this machine's), PROJ's database, and the shared DEMs the tests read
#     (../shared/data/dem). Build BUILD_DIR with -DERODEM_MPI=OFF -DERODEM_VIEWER=OFF
#     -DERODEM_PYTHON=OFF (no MPI launcher, VTK or Python to carry).
#   bash experiments/benchmarks/gpu_bundle.sh unpack BUNDLE BUILD_DIR
#     on the GPU machine, from the repository's root: unpacks BUNDLE into BUILD_DIR (so that
#     `gpu_check.sh BUILD_DIR` finds the binaries), points OpenCL's loader at the driver's
#     library (/etc/OpenCL/vendors/nvidia.icd -> libnvidia-opencl.so.1, found where the driver
#     put it) and puts the DEMs where the test binary looks for them (this build's
#     ERODEM_SHARED_DIR). Then run, in the same shell:
#       export LD_LIBRARY_PATH=$PWD/BUILD_DIR/lib PROJ_DATA=$PWD/BUILD_DIR/share/proj
set -euo pipefail
what=${1:?usage: gpu_bundle.sh pack BUILD_DIR OUT_DIR | unpack BUNDLE BUILD_DIR}
case $what in
pack)
  B=${2:?BUILD_DIR}
  OUT=${3:?OUT_DIR}
  bins=("$B/cli/erodem" "$B/tests/erodem_tests")
  for f in "${bins[@]}"; do [ -x "$f" ] || { echo "gpu_bundle: no $f (build it first)" >&2; exit 66; }; done
  stage=$(mktemp -d)
  trap 'rm -rf "$stage"' EXIT
  mkdir -p "$stage/cli" "$stage/tests" "$stage/lib" "$stage/share/proj" "$stage/dem"
  cp "$B/cli/erodem" "$stage/cli/"
  cp "$B/tests/erodem_tests" "$stage/tests/"
  # the libraries the loader resolves here, but not glibc's (libc, libm, the loader, ...)
  ldd "${bins[@]}" | awk '/=> \// {print $3}' | sort -u |
    grep -vE '/(libc|libm|libdl|librt|libpthread|libresolv|libutil|ld-linux[^/]*)\.so' |
    while read -r lib; do cp -L "$lib" "$stage/lib/"; done
  cp /usr/share/proj/proj.db "$stage/share/proj/"
  # where the test binary looks for the DEMs, as it was built (tests/CMakeLists.txt)
  shared=$(grep -o 'ERODEM_SHARED_DIR=[^ ]*' "$B/build.ninja" | head -1 | sed 's/^[^=]*=//; s/[\\"]//g')
  echo "$shared" > "$stage/shared_dir"
  cp -rL "$(dirname "$0")/../../../shared/data/dem/." "$stage/dem/"
  mkdir -p "$OUT"
  tar -C "$stage" -cJf "$OUT/bundle.tar.xz" .
  echo "gpu_bundle: $OUT/bundle.tar.xz, $(du -h "$OUT/bundle.tar.xz" | cut -f1)" \
    "($(ls "$stage/lib" | wc -l) libraries; DEMs for $shared)"
  ;;
unpack)
  BUNDLE=${2:?BUNDLE}
  B=${3:?BUILD_DIR}
  mkdir -p "$B"
  tar -C "$B" -xJf "$BUNDLE"
  icd=$(ldconfig -p | awk '/libnvidia-opencl\.so\.1 / {print $NF; exit}')
  [ -n "$icd" ] || icd=$(find / -xdev -name 'libnvidia-opencl.so.1' 2> /dev/null | head -1)
  [ -n "$icd" ] || { echo "gpu_bundle: no libnvidia-opencl.so.1 on this machine" >&2; exit 69; }
  mkdir -p /etc/OpenCL/vendors
  echo "$icd" > /etc/OpenCL/vendors/nvidia.icd
  shared=$(cat "$B/shared_dir")
  # the path may name a folder beside a checkout that is not here (".../main/../shared")
  mkdir -p "$(dirname "$shared")" "${shared%/../shared}" 2> /dev/null || true
  mkdir -p "$shared/data"
  # (DEMs already there, a real folder, are kept: never removed)
  [ -e "$shared/data/dem" ] && [ ! -L "$shared/data/dem" ] || ln -sfn "$PWD/$B/dem" "$shared/data/dem"
  echo "gpu_bundle: $B unpacked; OpenCL ICD $icd; DEMs at $shared/data/dem"
  ;;
*)
  echo "gpu_bundle: unknown action '$what' (pack or unpack)" >&2
  exit 2
  ;;
esac
