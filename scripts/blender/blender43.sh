#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Blender 4.3, Debian 13 "trixie"'s package, as a drop-in `blender` executable:
#   blender43.sh --setup | blender43.sh ARGS...      (see debian-blender.sh)
# $SSAO_TRIXIE_DIR, $SSAO_TRIXIE_BINDS and $SSAO_TRIXIE_ENV are the older names of
# $SSAO_DEBIAN_BLENDER_DIR, $SSAO_BLENDER_BINDS and $SSAO_BLENDER_ENV.
export SSAO_EXPECT_BLENDER=4.3
[[ -n "${SSAO_TRIXIE_DIR:-}" ]] && export SSAO_DEBIAN_BLENDER_DIR=$SSAO_TRIXIE_DIR
[[ -n "${SSAO_TRIXIE_BINDS:-}" ]] && export SSAO_BLENDER_BINDS=$SSAO_TRIXIE_BINDS
[[ -n "${SSAO_TRIXIE_ENV:-}" ]] && export SSAO_BLENDER_ENV=$SSAO_TRIXIE_ENV
exec "$(dirname "$(realpath "${BASH_SOURCE[0]}")")/debian-blender.sh" trixie "$@"
