# Install layout (GNUInstallDirs; docs/deploy.md) and the Debian package (CPack
# DEB; scripts/package.sh builds it). With CMAKE_INSTALL_PREFIX=/usr:
#   /usr/bin/marionette
#   /usr/share/marionette/            the default configs, programs, terrains, clips (read-only)
#   /etc/marionette/*.toml            the administrator's overrides (conffiles)
#   /usr/lib/udev/rules.d/70-marionette.rules
#   /usr/lib/systemd/system/marionette.service, /usr/lib/systemd/user/marionette-user.service
#   /usr/share/doc/marionette/        deploy.md, README.md
install(TARGETS marionette RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY "${PROJECT_SOURCE_DIR}/config/" DESTINATION ${CMAKE_INSTALL_DATADIR}/marionette)
# FULL_SYSCONFDIR is /etc for the /usr prefix (the relative one would give /usr/etc).
install(FILES "${PROJECT_SOURCE_DIR}/packaging/etc/marionette.toml" "${PROJECT_SOURCE_DIR}/packaging/etc/render.toml"
        DESTINATION "${CMAKE_INSTALL_FULL_SYSCONFDIR}/marionette")
install(FILES "${PROJECT_SOURCE_DIR}/packaging/udev/70-marionette.rules" DESTINATION lib/udev/rules.d)
install(FILES "${PROJECT_SOURCE_DIR}/packaging/systemd/marionette.service" DESTINATION lib/systemd/system)
install(FILES "${PROJECT_SOURCE_DIR}/packaging/systemd/marionette-user.service" DESTINATION lib/systemd/user)
install(FILES "${PROJECT_SOURCE_DIR}/docs/deploy.md" "${PROJECT_SOURCE_DIR}/README.md"
        DESTINATION ${CMAKE_INSTALL_DOCDIR})

set(CPACK_GENERATOR "DEB")
set(CPACK_PACKAGE_NAME "marionette")
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "controller-driven puppet runtime (kiosk and handheld)")
set(CPACK_PACKAGE_CONTACT "marionette maintainers <marionette@localhost>")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # marionette_VERSION_ARCH.deb
set(CPACK_DEBIAN_PACKAGE_SECTION "games")
# Depends from the shared libraries the binary links (dpkg-shlibdeps), plus
# passwd for the maintainer scripts' groupadd/useradd.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "passwd")
# Mesa's EGL/GBM drivers (KMS and window) and udev/systemd for the rules and units.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libegl-mesa0, libgl1-mesa-dri, udev, systemd")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    "${PROJECT_SOURCE_DIR}/packaging/debian/conffiles"
    "${PROJECT_SOURCE_DIR}/packaging/debian/postinst"
    "${PROJECT_SOURCE_DIR}/packaging/debian/postrm")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
set(CPACK_STRIP_FILES ON)
include(CPack)
