#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Blender 5.2 LTS, Debian sid's package, as a drop-in `blender` executable:
#   blender52.sh --setup | blender52.sh ARGS...      (see debian-blender.sh)
export SSAO_EXPECT_BLENDER=5.2
# 5.2's own extension manager (bl_pkg) imports cattrs, requests and urllib3 at start-up;
# without them every start prints a traceback (harmless, but it hides real ones).
export SSAO_BLENDER_EXTRA_PACKAGES="python3-cattr python3-requests python3-urllib3"
exec "$(dirname "$(realpath "${BASH_SOURCE[0]}")")/debian-blender.sh" sid "$@"
