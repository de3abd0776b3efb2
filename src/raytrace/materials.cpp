#include "raytrace/materials.h"

#include "util/errors.h"
#include "util/raypath.h"
#include "util/strings.h"

namespace dayflux {

namespace {

// The largest refractive index taken: beyond any material's (4 in the visible), far below the
// 1e19 whose square is no float (glass of 1e300 gave NaN).
constexpr double kMostIndex = 1e3;

// A roughness's square, the Gaussian lobe's alpha^2. Past a roughness of about 10 the lobe is
// as wide as it gets (the results do not change between 1e3 and 1e10); past 1e19 its square is
// no float (the GPU's, and the CPU's packed tables), and the sampled directions NaN. So it stops
// at 1e10 (a roughness of 1e5).
double RoughnessSquared(double roughness) { return std::min(roughness * roughness, 1e10); }

}  // namespace

SceneMaterials::SceneMaterials(const FlatScene &scene, const std::vector<TrackedModifier> &tracked)
    : scene_(scene), tracked_(tracked) {
    const auto &objs = scene_.scene.objects;
    materials_.resize(objs.size());
    tracked_of_object_.assign(objs.size(), -1);
    std::vector<int> pattern_of(objs.size(), -1);
    inside_counter_of_bit_.fill(-1);
    for (size_t i = 0; i < objs.size(); ++i) {
        const Primitive &p = objs[i];
        if (p.info->kind == PrimitiveKind::kSurface || p.info->kind == PrimitiveKind::kVolume) {
            tracked_of_object_[i] = TrackedIndex(p.modifier_name);
            materials_[i] = Resolved(p.modifier, pattern_of);
        }
    }
    clip_of_object_.assign(objs.size(), 0);
    for (size_t i = 0; i < objs.size(); ++i)
        if (auto it = clip_bits_.find(objs[i].modifier); it != clip_bits_.end())
            clip_of_object_[i] = uint64_t{1} << it->second;
    for (int mat : scene_.triangle_material)
        if (mat >= 0 && !tracked_of_mesh_material_.count(mat)) {
            Resolved(mat, pattern_of);
            tracked_of_mesh_material_[mat] = TrackedIndex(objs[mat].name);
        }
    // marksources(): the scene's own objects, not those of instances.
    for (const AnalyticShape &sh : scene_.shapes) {
        if (sh.kind != AnalyticShape::kSource || sh.object >= scene_.top_level_objects) continue;
        if (objs[sh.object].modifier < 0) continue;  // void: no source, as RADIANCE skips it
        CheckSourceEmits(sh.object);
        const double l = std::sqrt(sh.p0[0] * sh.p0[0] + sh.p0[1] * sh.p0[1] + sh.p0[2] * sh.p0[2]);
        // ssetsrc()'s checks
        if (!(l > 0))
            ErrorExit(&objs[sh.object].loc, "'" + objs[sh.object].name + "': zero direction");
        if (!(sh.r0 * (M_PI / 360.) > kTiny))
            ErrorExit(&objs[sh.object].loc, "'" + objs[sh.object].name + "': zero size");
        Source s;
        for (int k = 0; k < 3; ++k) s.dir[k] = sh.p0[k] / l;
        s.solid_angle = 2. * M_PI * (1. - std::cos(sh.r0 * (M_PI / 360.)));
        s.object = s.emitter = sh.object;
        s.skip = materials_[sh.object].kind == Material::kGlow;
        s.weak = s.skip || materials_[sh.object].kind == Material::kIllum;
        if (materials_[sh.object].spot_size > 0)  // RADIANCE warns too, and then ignores it
            Warning(&objs[sh.object].loc, "distant source is a spotlight");
        s.colour = materials_[sh.object].color;
        Tangents(s.dir, s.u, s.v);
        const double half_side = .5 * std::sqrt(s.solid_angle);
        for (int k = 0; k < 3; ++k) s.u[k] *= half_side, s.v[k] *= half_side;
        sources_.push_back(s);
    }
    // Light on local surfaces: sampled as area sources.
    for (size_t i = 0; i < static_cast<size_t>(scene_.top_level_objects); ++i) {
        const Material::Kind kind = materials_[i].kind;
        if ((kind == Material::kLight || kind == Material::kIllum) &&
            objs[i].info->kind == PrimitiveKind::kSurface && objs[i].type != "source" &&
            Max3(materials_[i].color) > kTiny)
            AddLocalSource(static_cast<int>(i));
    }
    WarnOfUnusedModifiers();
}

// A distant source whose material is not glow, light, illum or spotlight is no light source in
// RADIANCE (marksources() leaves it out, and a ray never reaches it); written so, it is almost
// always a mistake (a sky given the ground's plastic), so it is refused with its line.
void SceneMaterials::CheckSourceEmits(int object) const {
    const Material::Kind kind = materials_[object].kind;
    if (kind == Material::kGlow || kind == Material::kLight || kind == Material::kIllum) return;
    const auto &objs = scene_.scene.objects;
    int mod = objs[object].modifier;
    while (mod >= 0 && objs[mod].info->kind != PrimitiveKind::kMaterial &&
           objs[mod].info->kind != PrimitiveKind::kLight &&
           objs[mod].info->kind != PrimitiveKind::kMixture)
        mod = objs[mod].modifier;
    const std::string what = mod >= 0 ? objs[mod].type + " '" + objs[mod].name + "'" : "void";
    ErrorExit(&objs[object].loc, "source '" + objs[object].name + "': its material is " + what +
                                     ", which gives no light (a distant source needs glow, "
                                     "light, illum or spotlight)");
}

// RADIANCE gives a -m that no surface uses all-zero columns without a word; it is most often a
// misspelt or renamed modifier, so we say so.
void SceneMaterials::WarnOfUnusedModifiers() const {
    std::vector<bool> used(tracked_.size(), false);
    for (int k : tracked_of_object_)
        if (k >= 0) used[k] = true;
    for (const auto &[material, k] : tracked_of_mesh_material_)
        if (k >= 0) used[k] = true;
    for (size_t k = 0; k < tracked_.size(); ++k)
        if (!used[k])
            Warning("modifier '" + tracked_[k].name +
                    "' (-m) is used by no surface in the scene: its contributions are all zero");
}

// fsetsrc(), rsetsrc() and sphsetsrc(): a polygon's centre, normal, area and half-size vectors
// (half its first two edges for four vertices, else a square of its area), a ring's (a disc's),
// a sphere's; from the flattened scene, where transforms are applied.
void SceneMaterials::AddLocalSource(int object) {
    const Primitive &p = scene_.scene.objects[object];
    // A polygon's vertices; a ring's centre, normal, inner and outer radius; a sphere's centre
    // and radius; a cylinder's ends and radius: as its arguments are, transformed.
    std::vector<double> f;
    if (p.type == "polygon") {
        const FlatScene::VertexRange range = scene_.polygon_vertices[object];
        for (uint32_t v = range.first; v < range.first + range.count; ++v)
            f.insert(f.end(), scene_.vertices[v].begin(), scene_.vertices[v].end());
    } else {
        for (const AnalyticShape &sh : scene_.shapes) {
            if (sh.object != object) continue;
            f.assign(sh.p0.begin(), sh.p0.end());
            if (sh.kind == AnalyticShape::kRing) {
                f.insert(f.end(), sh.p1.begin(), sh.p1.end());
                f.push_back(sh.r0);
                f.push_back(sh.r1);
            } else if (sh.kind == AnalyticShape::kCylinder) {
                f.insert(f.end(), sh.p1.begin(), sh.p1.end());
                f.push_back(sh.r0);
            } else {
                f.push_back(sh.r0);
            }
            break;
        }
    }
    if (f.empty() && p.type != "polygon") return;  // a shape left out (a warning said why)
    Source s{};
    s.object = s.emitter = object;
    s.skip = false;
    s.weak = materials_[object].kind == Material::kIllum;
    s.colour = materials_[object].color;
    const auto square = [&s] {  // setflatss(): a square of the source's area about its normal
        Tangents(s.norm, s.ss[0], s.ss[1]);
        s.turned = true;
        const double mult = .5 * std::sqrt(s.area);
        for (int k = 0; k < 3; ++k) s.ss[0][k] *= mult, s.ss[1][k] *= mult;
    };
    if (p.type == "polygon") {
        const size_t nv = f.size() / 3;
        if (nv < 3) ErrorExit(&p.loc, "'" + p.name + "': zero source area");
        double c[3] = {0, 0, 0}, a[3] = {0, 0, 0};
        for (size_t v = 0; v < nv; ++v)
            for (int k = 0; k < 3; ++k) c[k] += f[3 * v + k] / nv;
        for (size_t v = 1; v + 1 < nv; ++v) {
            double e1[3], e2[3];
            for (int k = 0; k < 3; ++k)
                e1[k] = f[3 * v + k] - f[k], e2[k] = f[3 * (v + 1) + k] - f[k];
            a[0] += .5 * (e1[1] * e2[2] - e1[2] * e2[1]);
            a[1] += .5 * (e1[2] * e2[0] - e1[0] * e2[2]);
            a[2] += .5 * (e1[0] * e2[1] - e1[1] * e2[0]);
        }
        s.area = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        if (s.area == 0) ErrorExit(&p.loc, "'" + p.name + "': zero source area");
        s.shape = Source::kFlat;
        for (int k = 0; k < 3; ++k) s.loc[k] = c[k], s.norm[k] = a[k] / s.area;
        if (nv == 4) {
            for (int k = 0; k < 3; ++k) {
                s.ss[0][k] = .5 * (f[3 + k] - f[k]);
                s.ss[1][k] = .5 * (f[9 + k] - f[k]);
            }
        } else {
            square();
        }
    } else if (p.type == "ring") {
        if (f[6] > 0) ErrorExit(&p.loc, "'" + p.name + "': cannot hit source center");
        const double l = std::sqrt(f[3] * f[3] + f[4] * f[4] + f[5] * f[5]);
        s.shape = Source::kFlat;
        s.circular = true;
        for (int k = 0; k < 3; ++k) s.loc[k] = f[k], s.norm[k] = f[3 + k] / l;
        s.area = M_PI * f[7] * f[7];
        square();
    } else if (p.type == "sphere") {
        if (f[3] <= kTiny) ErrorExit(&p.loc, "'" + p.name + "': illegal source radius");
        s.shape = Source::kSphere;
        s.circular = true;
        for (int k = 0; k < 3; ++k) s.loc[k] = f[k];
        s.area = M_PI * f[3] * f[3];
        for (int k = 0; k < 3; ++k) s.ss[k][k] = 0.7236 * f[3];
    } else if (p.type == "cylinder") {  // cylsetsrc()
        const double r0 = f[6];
        double ad[3] = {f[3] - f[0], f[4] - f[1], f[5] - f[2]};
        const double al = std::sqrt(ad[0] * ad[0] + ad[1] * ad[1] + ad[2] * ad[2]);
        if (r0 <= kTiny || al <= 0) ErrorExit(&p.loc, "'" + p.name + "': illegal source radius");
        if (r0 > .2 * al) Warning(&p.loc, "'" + p.name + "': source aspect too small");
        s.shape = Source::kCylinder;
        s.turned = true;
        for (int k = 0; k < 3; ++k) {
            ad[k] /= al;
            s.axis[k] = ad[k];
            s.loc[k] = .5 * (f[k] + f[3 + k]);
            s.ss[0][k] = .5 * al * ad[k];
        }
        s.area = 2. * r0 * al;  // its projected area
        s.radius = r0;
    } else {
        ErrorExit(&p.loc, p.type + " '" + p.name +
                              "': illegal material for a light source (RADIANCE samples lights on "
                              "polygons, rings, spheres and cylinders only)");
    }
    // checkspot(): a flat spotlight aimed behind itself never lights anything.
    const Material &m = materials_[object];
    if (m.spot_size > 0 && s.shape == Source::kFlat) {
        const double d =
            m.spot_aim[0] * s.norm[0] + m.spot_aim[1] * s.norm[1] + m.spot_aim[2] * s.norm[2];
        const double d1 = 1. - m.spot_size / (2. * M_PI);
        if (!(d > kTiny || 1. - kTiny - d * d < d1 * d1)) {
            Warning(&p.loc, "'" + p.name + "': invalid spotlight direction");
            s.skip = true;
        }
    }
    sources_.push_back(s);
}

// The last modifier of that name before object `before` (how RADIANCE finds the materials a
// mixfunc or an illum names).
int SceneMaterials::LastModifier(int before, const std::string &name) const {
    const auto &objs = scene_.scene.objects;
    int j = before - 1;
    while (j >= 0 && !(objs[j].name == name && objs[j].info->kind != PrimitiveKind::kSurface &&
                       objs[j].info->kind != PrimitiveKind::kVolume))
        --j;
    return j;
}

int SceneMaterials::FindModifier(int before, const std::string &name, const FileLoc &loc) const {
    const int j = LastModifier(before, name);
    if (j < 0) ErrorExit(&loc, "undefined modifier '" + name + "'");
    return j;
}

int SceneMaterials::TrackedIndex(const std::string &modifier) const {
    int found = -1;
    for (size_t k = 0; k < tracked_.size(); ++k)
        if (modifier == tracked_[k].name) found = static_cast<int>(k);
    return found;
}

// Resolve, once per modifier (a mixfunc loads its files, many surfaces share a modifier).
const Material &SceneMaterials::Resolved(int mod, std::vector<int> &pattern_of) {
    auto it = by_modifier_.find(mod);
    if (it == by_modifier_.end()) it = by_modifier_.emplace(mod, Resolve(mod, pattern_of)).first;
    return it->second;
}

// The material a surface's modifier stands for, with the patterns that modify it.
Material SceneMaterials::Resolve(int mod, std::vector<int> &pattern_of) {
    const auto &objs = scene_.scene.objects;
    Material m;
    while (mod >= 0 && objs[mod].type == "alias")
        mod = objs[mod].modifier >= 0 ? objs[mod].modifier : -1;
    if (mod < 0) return m;  // void: absorbs
    const Primitive &p = objs[mod];
    const auto &f = p.fargs;
    const std::string &t = p.type;
    if ((t == "plastic" || t == "metal" || t == "trans") && f[3] > 1)
        // (RADIANCE takes it: such a surface reflects more than it receives, and light
        // between two of them grows without end)
        Warning(&p.loc, t + " '" + p.name + "': a specularity above 1");
    if (t == "plastic" || t == "metal") {
        m.kind = Material::kDiffuse;
        m.color = {f[0], f[1], f[2]};
        m.spec = f[3];
        m.metal = t == "metal";
        m.alpha2 = RoughnessSquared(f[4]);
    } else if (t == "trans") {
        m.kind = Material::kDiffuse;
        m.color = {f[0], f[1], f[2]};
        m.spec = f[3];
        m.trans = f[5];
        m.transparent = true;
        m.tspec = f[6];
        m.alpha2 = RoughnessSquared(f[4]);
    } else if (t == "mixfunc") {
        if (p.sargs.size() > 4)
            ErrorExit(&p.loc, "mixfunc '" + p.name +
                                  "': transforms of its coordinates are not supported yet");
        auto info = std::make_unique<MixInfo>();
        for (int side = 0; side < 2; ++side) {
            const std::string &name = p.sargs[side];
            if (name == "void") {
                info->is_void[side] = true;
                continue;
            }
            (side == 0 ? info->fore : info->back) =
                Resolved(FindModifier(mod, name, p.loc), pattern_of);
        }
        Primitive f = p;  // the coefficient, evaluated as a brightfunc would be
        f.type = "brightfunc";
        f.info = FindPrimitiveType("brightfunc");
        f.modifier = -1;
        f.sargs = {p.sargs[2], p.sargs[3]};
        info->coef = std::make_unique<PatternFunction>(f);
        m.kind = Material::kMix;
        m.mix = info.get();
        mixes_.push_back(std::move(info));
        if (p.modifier >= 0) ErrorExit(&p.loc, "mixfunc '" + p.name + "': inappropriate modifier");
        return m;
    } else if (t == "BSDF" || t == "aBSDF") {
        // BSDF: 6+ thick file ux uy uz funcfile [transform]; aBSDF: 5+ file ux uy uz funcfile
        // [transform] (no thickness); 0; 0|3|6|9 diffuse colours
        const size_t file = t == "BSDF" ? 1 : 0;
        if (p.sargs.size() < file + 5 || f.size() > 9 || f.size() % 3)
            ErrorExit(&p.loc, t + " '" + p.name + "': bad # arguments");
        auto info = std::make_unique<BsdfInfo>();
        info->proxy = file == 1 && p.sargs[0] != "0";
        // A thickness (metres) beyond any window's moves rays beyond float (Embree refuses them).
        if (double thick;
            file == 1 && ParseNumber(p.sargs[0], &thick) && !(std::fabs(thick) <= 1e3))
            ErrorExit(&p.loc, t + " '" + p.name + "': thickness " + p.sargs[0] +
                                  " is beyond any window's (at most 1000)");
        info->aperture = file == 0;
        info->name = p.name;
        std::string path;
        try {
            path = FindOnRaypath(p.sargs[file]);
        } catch (const UserError &e) {
            ErrorExit(&p.loc, t + " '" + p.name + "': " + e.what());
        }
        auto &klems = klems_by_path_[path];
        if (!klems) klems = std::make_shared<const KlemsScattering>(LoadKlemsBsdf(path));
        info->klems = klems;
        Primitive e = p;  // thickness and up vector, evaluated as patterns are
        e.type = "brightfunc";
        e.info = FindPrimitiveType("brightfunc");
        e.modifier = -1;
        e.sargs = {file == 1 ? p.sargs[0] : "0", p.sargs[file + 4]};
        info->thickness = std::make_unique<PatternFunction>(e);
        e.type = "colorfunc";
        e.info = FindPrimitiveType("colorfunc");
        e.sargs = {p.sargs[file + 1], p.sargs[file + 2], p.sargs[file + 3], p.sargs[file + 4]};
        if (p.sargs.size() > file + 5)
            ErrorExit(&p.loc,
                      t + " '" + p.name + "': transforms of its up vector are not supported yet");
        info->up = std::make_unique<PatternFunction>(e);
        for (size_t k = 0; k < f.size(); ++k) {
            RGB &c = k < 3   ? info->front_reflection
                     : k < 6 ? info->back_reflection
                             : info->transmission;
            c[k % 3] = f[k];
        }
        m.kind = Material::kBsdf;
        m.color = {1, 1, 1};
        m.bsdf = info.get();
        bsdfs_.push_back(std::move(info));
    } else if (t == "glass") {
        m.kind = Material::kGlass;
        m.transparent = true;
        m.color = {f[0], f[1], f[2]};
        if (f.size() == 4) m.rindex = f[3];
        // m_glass()'s transmitted cosine is the root of 1 - (1 - cos^2) / n^2: below 1 it has
        // none at grazing angles (RADIANCE gives NaN there).
        if (!(m.rindex >= 1 && m.rindex <= kMostIndex))
            ErrorExit(&p.loc, "glass '" + p.name + "': refractive index " + FormatNumber(m.rindex) +
                                  (m.rindex < 1 ? " is below 1" : " is beyond any material's"));
    } else if (t == "dielectric") {
        if (f.size() != 5) ErrorExit(&p.loc, "dielectric '" + p.name + "': bad arguments");
        const double index = f[3] + f[4] / 500.;
        if (!(index > 0 && index <= kMostIndex))
            ErrorExit(&p.loc, "dielectric '" + p.name + "': refractive index " +
                                  FormatNumber(index) +
                                  (index > 0 ? " is beyond any material's" : " is not above 0"));
        m.kind = Material::kDielectric;
        m.color = {f[0], f[1], f[2]};
        m.rindex = index;
        m.transparent = true;
    } else if (t == "mirror") {
        if (f.size() != 3 || p.sargs.size() > 1)
            ErrorExit(&p.loc, "mirror '" + p.name + "': bad number of arguments");
        m.kind = Material::kMirror;
        m.color = {f[0], f[1], f[2]};
        if (!p.sargs.empty()) {
            m.mirror_alternate = true;
            if (p.sargs[0] != "void")
                m.alternate = &Resolved(FindModifier(mod, p.sargs[0], p.loc), pattern_of);
        }
    } else if (t == "glow") {
        m.kind = Material::kGlow;
        m.color = {f[0], f[1], f[2]};
    } else if (t == "light") {
        m.kind = Material::kLight;
        m.color = {f[0], f[1], f[2]};
    } else if (t == "spotlight") {
        if (f.size() != 7) ErrorExit(&p.loc, "spotlight '" + p.name + "': bad # arguments");
        if (f[3] <= kTiny) ErrorExit(&p.loc, "spotlight '" + p.name + "': zero angle");
        // The focus vector as xform leaves it (turned and scaled with the spotlight).
        double aim[3];
        p.xf.ApplyDirection(&f[4], aim);
        const double l = std::sqrt(aim[0] * aim[0] + aim[1] * aim[1] + aim[2] * aim[2]);
        if (l == 0) ErrorExit(&p.loc, "spotlight '" + p.name + "': zero focus vector");
        m.kind = Material::kLight;  // makespot()
        m.color = {f[0], f[1], f[2]};
        m.spot_size = 2. * M_PI * (1. - std::cos(M_PI / 180. / 2. * f[3]));
        m.spot_aim = {aim[0] / l, aim[1] / l, aim[2] / l};
        m.spot_flen = l;
    } else if (t == "antimatter") {
        // m_clip(): its front adds the modifiers named (void aside) to the set a ray passes
        // through unseen, its back takes them away. A first modifier other than void is also
        // what a ray meets there when it went into one of them on its way (RADIANCE counts the
        // fronts minus the backs of their surfaces that the ray and its unreflected ancestors
        // passed): the inside of the cut.
        if (p.sargs.empty()) ErrorExit(&p.loc, "antimatter '" + p.name + "': bad # arguments");
        m.kind = Material::kAntimatter;
        for (const std::string &name : p.sargs) {
            if (name == "void") continue;
            const int j = LastModifier(mod, name);  // RADIANCE warns, and goes on
            if (j < 0) {
                Warning(&p.loc, "antimatter '" + p.name + "': unknown modifier \"" + name + "\"");
                continue;
            }
            const int bit =
                clip_bits_.emplace(j, static_cast<int>(clip_bits_.size())).first->second;
            // The core's clip sets are 32 bits (RADIANCE's are sets of any size).
            if (bit >= 32) ErrorExit(&p.loc, "antimatter: more than 32 modifiers clipped");
            m.clip_mask |= uint64_t{1} << bit;
        }
        if (const int inside = p.sargs[0] == "void" ? -1 : LastModifier(mod, p.sargs[0]);
            inside >= 0) {
            m.alternate = &Resolved(inside, pattern_of);
            for (int bit = 0; bit < 64; ++bit) {
                if (!(m.clip_mask >> bit & 1)) continue;
                if (inside_counter_of_bit_[bit] < 0) {
                    if (inside_counters_ == kInsideCounters)
                        ErrorExit(&p.loc, "antimatter '" + p.name + "': more than " +
                                              std::to_string(kInsideCounters) +
                                              " modifiers clipped by antimatter with a material "
                                              "for its inside");
                    inside_counter_of_bit_[bit] = static_cast<int8_t>(inside_counters_++);
                }
                m.inside_counters |= 1u << inside_counter_of_bit_[bit];
            }
        }
    } else if (t == "illum") {
        m.kind = Material::kIllum;
        m.color = {f[0], f[1], f[2]};
        if (!p.sargs.empty() && p.sargs[0] != "void")
            m.alternate = &Resolved(FindModifier(mod, p.sargs[0], p.loc), pattern_of);
    } else {
        ErrorExit(&p.loc, "material type " + t + " ('" + p.name + "') is not traced yet");
    }
    // A pattern modifying the material (brightfunc, colorfunc).
    int pm = p.modifier;
    while (pm >= 0 && objs[pm].type == "alias") pm = objs[pm].modifier;
    if (pm >= 0) {
        const Primitive &pp = objs[pm];
        if (pp.type != "brightfunc" && pp.type != "colorfunc")
            ErrorExit(&pp.loc,
                      pp.type + " '" + pp.name + "' as a material modifier is not traced yet");
        if (pattern_of[pm] < 0) {
            pattern_of[pm] = static_cast<int>(patterns_.size());
            patterns_.push_back(std::make_unique<PatternFunction>(pp));
        }
        m.pattern = patterns_[pattern_of[pm]].get();
        if (pp.modifier >= 0) ErrorExit(&pp.loc, "chains of patterns are not traced yet");
    }
    return m;
}

}  // namespace dayflux
