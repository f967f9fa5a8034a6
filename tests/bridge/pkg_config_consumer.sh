#!/bin/sh
# Builds bridge_c_test.c the way a C firmware project would: flags from the pliant-bridge.pc
# file that `cmake --install` installs, with its libdir and includedir pointed at the build
# tree (pkg-config --define-variable), then runs it.
# Usage: pkg_config_consumer.sh PC_DIR LIBDIR INCLUDEDIR C_COMPILER SOURCE OUTPUT EXTRA_FLAGS [EMULATOR...]
# EXTRA_FLAGS (may be empty) are the flags the libraries were built with that a consumer must
# repeat, e.g. -fsanitize=address,undefined; EMULATOR runs a cross-built program (qemu-aarch64).
set -eu
pc_dir=$1
libdir=$2
includedir=$3
cc=$4
source=$5
output=$6
extra_flags=$7
shift 7
flags=$(PKG_CONFIG_PATH="$pc_dir" PKG_CONFIG_DISABLE_UNINSTALLED=1 pkg-config \
  --define-variable=libdir="$libdir" --define-variable=includedir="$includedir" --cflags --libs pliant-bridge)
echo "pkg-config pliant-bridge: $flags"
# shellcheck disable=SC2086  # flags are words
# shellcheck disable=SC2086  # extra_flags are words
"$cc" -std=c99 -pedantic -Wall -Wextra -Werror $extra_flags "$source" -o "$output" $flags
"$@" "$output"
