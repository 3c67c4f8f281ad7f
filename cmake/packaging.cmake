# `cpack -G DEB` in the build folder: a Debian package of the installed tree (weft in /usr/bin, its
# bundled data in /usr/share/weft, the README and docs in /usr/share/doc/weft).
install(FILES README.md DESTINATION share/doc/weft)
install(DIRECTORY docs/ DESTINATION share/doc/weft/docs)

set(CPACK_PACKAGE_NAME weft)
set(CPACK_PACKAGE_VENDOR "Weft")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Physically based fabric appearance pipeline and renderer")
set(CPACK_PACKAGE_INSTALL_DIRECTORY weft)
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "Weft maintainers <weft@localhost>"
    CACHE STRING "the Maintainer field of the .deb")
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "Fiber physics (Mie scattering, photon transport) to fiber and fabric BSDF tables, an Embree
path tracer that renders them, and weft verify, which sets a computed fabric beside a measured
one. The bundled measured fabrics, verify suite, example scenes and plot scripts are in
/usr/share/weft.")
# The Debian 12 packages of the libraries weft links (dpkg-shlibdeps on the built program gives
# these, with these lower bounds). The plot scripts of weft verify and weft compare need python3
# with matplotlib; without them the other commands still run. The Python module (in
# /usr/lib/python3/dist-packages, for Debian's python3) needs numpy for its tables' values.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libc6 (>= 2.35), libembree3-3 (>= 3.13.5+dfsg), libgcc-s1 (>= 4.0), \
libopenexr-3-1-30 (>= 3.1.5), libopenimageio2.4 (>= 2.4.7.1+dfsg), libstdc++6 (>= 11), \
libtbb12 (>= 2021.4.0), libtinygltf2d (>= 2.7.0+dfsg)")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "python3, python3-matplotlib, python3-numpy")
include(CPack)
