# SPDX-License-Identifier: MIT
# cmake -DSOURCES="a;b" -DSTAGE=dir -DVERSION=x.y.z -DPLATFORMS="linux-x64;windows-x64"
# -P stage.cmake: copies the add-on's files into STAGE, writing the project's version into
# bl_info and blender_manifest.toml (the one place the version lives is project() in the
# top-level CMakeLists.txt) and the platforms whose library the zip carries into the manifest.
string(REPLACE "." ", " version_tuple "${VERSION}")
list(TRANSFORM PLATFORMS REPLACE "(.+)" "\"\\1\"" OUTPUT_VARIABLE quoted_platforms)
list(JOIN quoted_platforms ", " platform_list)
foreach(source IN LISTS SOURCES)
  get_filename_component(name "${source}" NAME)
  file(READ "${source}" text)
  if(name STREQUAL "__init__.py")
    string(REGEX REPLACE "\"version\": \\([0-9, ]+\\)" "\"version\": (${version_tuple})"
           text "${text}")
  elseif(name STREQUAL "blender_manifest.toml")
    string(REGEX REPLACE "\nversion = \"[0-9.]+\"" "\nversion = \"${VERSION}\"" text "${text}")
    string(REGEX REPLACE "\nplatforms = \\[[^]\n]*\\]" "\nplatforms = [${platform_list}]"
           text "${text}")
  endif()
  file(WRITE "${STAGE}/${name}" "${text}")
endforeach()
