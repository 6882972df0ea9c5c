# The Python package `collide` as a wheel installs it (pyproject.toml: scikit-build-core sets
# LIBCOLLIDE_BUILD_PYTHON and takes the install component "python" alone): the package's Python
# files, the cffi extension _collide_cffi and the libcollide.so it links, side by side in collide/,
# the extension finding the library through RUNPATH $ORIGIN. The cdef and the C source come from
# ros_pkg/collide/build_ffi.py, the same generator a source checkout's `python -m collide.build_ffi`
# uses, so both ways give one binding.
find_package(Python 3.11 REQUIRED COMPONENTS Interpreter Development.Module)

set(LC_PY_PACKAGE_DIR ${CMAKE_CURRENT_SOURCE_DIR}/ros_pkg/collide)
set(LC_CFFI_SOURCE ${CMAKE_CURRENT_BINARY_DIR}/cffi/_collide_cffi.c)
file(GLOB LC_PUBLIC_HEADERS CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/libcollide/include/collide/*.h)

# CC is the compiler that preprocesses the public header into the cdef; -B leaves no __pycache__
# in the source tree.
add_custom_command(OUTPUT ${LC_CFFI_SOURCE}
  COMMAND ${CMAKE_COMMAND} -E env "CC=${CMAKE_C_COMPILER}"
          ${Python_EXECUTABLE} -B ${LC_PY_PACKAGE_DIR}/build_ffi.py --emit-c ${LC_CFFI_SOURCE}
  DEPENDS ${LC_PUBLIC_HEADERS} ${LC_PY_PACKAGE_DIR}/build_ffi.py
  COMMENT "Generating the cffi source of collide._collide_cffi"
  VERBATIM)

Python_add_library(_collide_cffi MODULE WITH_SOABI ${LC_CFFI_SOURCE})
target_link_libraries(_collide_cffi PRIVATE collide)
# as the source checkout's build compiles it; cffi's generated code is not held to LC_C_FLAGS
target_compile_options(_collide_cffi PRIVATE -ffp-contract=off)
set_target_properties(_collide_cffi PROPERTIES INSTALL_RPATH "$ORIGIN")

install(TARGETS _collide_cffi LIBRARY DESTINATION collide COMPONENT python)
# A wheel holds no symlinks: the library goes in once, under the name the extension asks for (SONAME).
install(FILES $<TARGET_FILE:collide> DESTINATION collide
  RENAME ${CMAKE_SHARED_LIBRARY_PREFIX}collide${CMAKE_SHARED_LIBRARY_SUFFIX}.${PROJECT_VERSION_MAJOR}
  COMPONENT python)
install(DIRECTORY ${LC_PY_PACKAGE_DIR}/ DESTINATION collide COMPONENT python
  FILES_MATCHING PATTERN "*.py"
  PATTERN "__pycache__" EXCLUDE)
