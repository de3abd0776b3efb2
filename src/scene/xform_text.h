// What RADIANCE's xform prints for a primitive (gen/xform.c), as oconv reads it back: a primitive
// that came through "!xform" has its arguments transformed by its type's rule and rounded to
// xform's precision, and functions and instances carry the transform's options. Frozen octrees
// store these numbers, so ours must too to hold RADIANCE's bytes.
#pragma once

#include "scene/primitives.h"

namespace dayflux {

// Whether xform writes its transform's options into objects of this type (addxform(): functions,
// data and pictures, instances and meshes).
bool XformAddsTransform(const std::string &type);

// p with its transforms applied as each xform in turn writes it (p.xf left as it was, for the
// engine); p itself where it did not come through "!xform".
Primitive AsXformPrints(const Primitive &p);

}  // namespace dayflux
