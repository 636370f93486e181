# Provides the OpenSubdiv::osdCPU target. Debian 12's OpenSubdivTargets.cmake also imports static libraries
# the package does not ship (libosdCPU.a, libosdGPU.a), and CMake stops with a fatal error on the missing
# files, so that config file cannot be used there. Where the shared CPU library and its headers are found,
# import them under the config's own target name; elsewhere use OpenSubdiv's config.
# Used by the build and by the installed DeformKitConfig.cmake (static deformkit::core links it).
if(NOT TARGET OpenSubdiv::osdCPU)
    find_path(OpenSubdiv_INCLUDE_DIR opensubdiv/version.h)
    find_library(OpenSubdiv_osdCPU_LIBRARY NAMES osdCPU)
    if(OpenSubdiv_INCLUDE_DIR AND OpenSubdiv_osdCPU_LIBRARY)
        file(STRINGS "${OpenSubdiv_INCLUDE_DIR}/opensubdiv/version.h" _osd_version_line
             REGEX "^#define OPENSUBDIV_VERSION_NUMBER [0-9]+")
        string(REGEX REPLACE "^#define OPENSUBDIV_VERSION_NUMBER ([0-9]+).*" "\\1" _osd_version "${_osd_version_line}")
        if(NOT _osd_version OR _osd_version LESS 30500)
            message(FATAL_ERROR "DeformKit needs OpenSubdiv 3.5 or newer; found version number '${_osd_version}' "
                                "in ${OpenSubdiv_INCLUDE_DIR}/opensubdiv/version.h")
        endif()
        add_library(OpenSubdiv::osdCPU UNKNOWN IMPORTED)
        set_target_properties(OpenSubdiv::osdCPU PROPERTIES
            IMPORTED_LOCATION "${OpenSubdiv_osdCPU_LIBRARY}"
            INTERFACE_INCLUDE_DIRECTORIES "${OpenSubdiv_INCLUDE_DIR}")
    else()
        find_package(OpenSubdiv 3.5 REQUIRED CONFIG)
    endif()
endif()
