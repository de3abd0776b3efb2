// The common subset of C++ and GLSL that the estimator core (src/raytrace/core) is written in, as
// NVIDIA's nvpro-samples shader headers are: GLM gives C++ GLSL's types and function names, and a
// few macros cover what differs.
//   real, real2, real3, real4  the estimator's arithmetic: double in C++, float in GLSL
//   cal_real                   the calcomp functions' (bins, patterns): double in C++; in GLSL
//                              float, or double where a run asks (the host defines it)
//   IN(T), OUT(T), INOUT(T)    GLSL's in, out and inout parameters (C++: a const reference for
//                              in, since GLSL copies what C++ would; references for the others)
//   CONST                      a constant at file or class scope
//   DONT_UNROLL                keeps a loop rolled in GLSL (lavapipe inlines every call, so
//                              small loops copied many times cost minutes of compiling)
//   PRECISE                    GLSL's precise: no multiply-add fused, so that the same
//                              expression written in two places gives the same bits
//   XYZ(v), XY(v), ZW(v)       swizzles (GLM has them only as proxies that templates reject)
//   LOCAL(T)                   a local bound to a table's entry: a const reference in C++ (no
//                              copy), a copy in GLSL (which has no references)
// Rules the core keeps so that both compilers take it: no recursion, no pointers, no default
// arguments, GLSL's forward declarations inside #ifndef __cplusplus (C++ class scope must not
// repeat a member's declaration), no swizzles but the macros above, no integer times vector (GLM's
// operators want one scalar type), every conversion between real and float written out where
// vectors meet.
//
// Files of the core come in two kinds. Headers (language.h, parameters.h, tables.h, random.h,
// sampling.h, shapes.h) hold constants, data layouts and pure functions at namespace scope, which
// C++ code and tests call directly. Fragments (*.inl) hold the estimator's state and the
// functions that use it: a GLSL shader includes them at file scope, where that state is one
// invocation's; C++ includes them inside a class body, so that each object holds one thread's
// state (see raytrace/core/README.md for what a driver provides around them).
#ifndef DAYFLUX_CORE_LANGUAGE_H
#define DAYFLUX_CORE_LANGUAGE_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>

namespace dayflux::core {
using uint = uint32_t;
using glm::bvec3;
using glm::ivec2;
using glm::ivec3;
using glm::ivec4;
using glm::uvec4;
using glm::vec2;
using glm::vec3;
using glm::vec4;
using real = double;
using real2 = glm::dvec2;
using real3 = glm::dvec3;
using real4 = glm::dvec4;
using cal_real = double;

using glm::abs;
using glm::acos;
using glm::asin;
using glm::atan;
using glm::clamp;
using glm::cos;
using glm::cross;
using glm::degrees;
using glm::dot;
using glm::exp;
using glm::floor;
using glm::length;
using glm::log;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
using glm::sin;
using glm::sqrt;

// Scalar abs without a branch: GLM's is x >= 0 ? x : -x, which GCC compiles to a jump, and the
// disk map's signs are random (half of them mispredicted, 7 % of a cell's direction).
inline double abs(double x) { return __builtin_fabs(x); }
inline float abs(float x) { return __builtin_fabsf(x); }
inline int abs(int x) { return x < 0 ? -x : x; }

inline real3 XYZ(const vec4 &v) { return real3(v.x, v.y, v.z); }
inline real2 XY(const vec4 &v) { return real2(v.x, v.y); }
inline ivec2 XY(const ivec4 &v) { return ivec2(v.x, v.y); }
inline ivec2 ZW(const ivec4 &v) { return ivec2(v.z, v.w); }
}  // namespace dayflux::core

#define IN(T) const T &
#define LOCAL(T) const T &
#define OUT(T) T &
#define INOUT(T) T &
#define CONST static constexpr
#define DONT_UNROLL
#define PRECISE

#else  // GLSL

#define real float
#define real2 vec2
#define real3 vec3
#define real4 vec4
#define IN(T) in T
#define LOCAL(T) T
#define OUT(T) out T
#define INOUT(T) inout T
#define CONST const
#define DONT_UNROLL [[dont_unroll]]
#define PRECISE precise
#define XYZ(v) (v).xyz
#define XY(v) (v).xy
#define ZW(v) (v).zw
#define inline

#endif
#endif  // DAYFLUX_CORE_LANGUAGE_H
