# SPDX-License-Identifier: MIT
# The Debian package (CPack's DEB generator): one package, ssao, with everything `cmake --install`
# installs (the library, its headers, CMake package and pkg-config file, the image codec module,
# ssao, povray-ssao and the Python module ssao). scripts/package.sh builds it in a tree of its
# own configured with the prefix /usr, so that GNUInstallDirs gives the multiarch libdir
# (lib/x86_64-linux-gnu) and the tools' run path ($ORIGIN/../${CMAKE_INSTALL_LIBDIR}) points
# there; docs/install.md.
#
# Run-time dependencies come from dpkg-shlibdeps (libopenimageio2.4, libtbb12, libstdc++6, ...),
# so `apt-get install ./ssao_VERSION_ARCH.deb` pulls what it needs from Debian's archive.

set(SSAO_PACKAGE_MAINTAINER
    "ssao maintainers <maintainers@users.noreply.h-seed-0f0aa172.example>"
    CACHE STRING "The Maintainer field of the Debian package")

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME ssao)
set(CPACK_PACKAGE_VENDOR "ssao")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Screen-space ambient occlusion for offline renders (library and tools)")
set(CPACK_PACKAGE_CONTACT "${SSAO_PACKAGE_MAINTAINER}")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
# Every file installed, in one package (no components).
set(CPACK_DEB_COMPONENT_INSTALL OFF)
set(CPACK_STRIP_FILES OFF)

set(CPACK_DEBIAN_PACKAGE_NAME ssao)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT) # ssao_0.1.0_amd64.deb
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "${SSAO_PACKAGE_MAINTAINER}")
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# The extended description; CPack puts the summary above it and indents it as Debian wants.
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "Ambient occlusion computed from a render's depth pass (and normal pass, when
there is one), for compositing Blender renders, post-processing POV-Ray
renders and pipelines that render headless.

This package holds libssao (a C++17 shared library with a stable C API), its
headers, CMake package and pkg-config file, the ssao command-line tool for EXR
files and sequences (render farms: --chunk-size, --chunk-index), the
povray-ssao filter, which needs POV-Ray, and the Python module ssao, which
needs numpy.")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# libssao.so.0 is in this package: a shlibs file lets other packages depend on it.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")
# povray-ssao runs POV-Ray, the Python module needs numpy; the library and ssao need neither.
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "povray, python3-numpy, pkg-config")

# The module's bytecode cache, written when root imports it, is removed with the package.
set(SSAO_PACKAGE_PYTHON_MODULE "${CPACK_PACKAGING_INSTALL_PREFIX}/${SSAO_PYTHONDIR}/ssao")
configure_file(${CMAKE_CURRENT_LIST_DIR}/debian/prerm.in ${CMAKE_BINARY_DIR}/debian/prerm @ONLY
               FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE
                                WORLD_READ WORLD_EXECUTE)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${CMAKE_BINARY_DIR}/debian/prerm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)

include(CPack)
