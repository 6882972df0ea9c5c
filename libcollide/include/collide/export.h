/* libcollide: LC_API marks the functions of the public API.
 * The shared library is compiled with hidden visibility by default (CMake C_VISIBILITY_PRESET
 * hidden) and with LC_BUILDING_SHARED defined, so that only the functions declared LC_API in these
 * headers are exported from libcollide.so; the engine's internal functions stay inside it. In every
 * other build (the static library, programs that use either library, the Python binding's cffi
 * extension) LC_API expands to nothing. */
#ifndef COLLIDE_EXPORT_H
#define COLLIDE_EXPORT_H

#if defined(LC_BUILDING_SHARED) && (defined(__GNUC__) || defined(__clang__))
#define LC_API __attribute__((visibility("default")))
#else
#define LC_API
#endif

#endif /* COLLIDE_EXPORT_H */
