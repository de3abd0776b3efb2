#include "bsdf/genbsdf.h"

#include <stdlib.h>   // mkdtemp
#include <strings.h>  // strcasecmp

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <sstream>

#include "matrix/bsdf_xml.h"
#include "matrix/matrices.h"
#include "matrix/operations.h"
#include "rcontrib/options.h"
#include "rfluxmtx/run.h"
#include "scene/flatten.h"
#include "scene/reader.h"
#include "util/errors.h"
#include "util/strings.h"

namespace dayflux {
namespace {

bool EqualsIgnoreCase(const std::string &a, const std::string &b) {
    return strcasecmp(a.c_str(), b.c_str()) == 0;
}

namespace fs = std::filesystem;

// genBSDF.pl's own numbers.
constexpr double kFeps = 1e-5;  // the senders' distance from the system's box
const char *const kRfluxmtxDefaults[] = {"-ab", "5", "-ad", "700", "-lw", "3e-6", "-w-"};
// Photopic Y, CIE X and Z from RADIANCE RGB (genBSDF's rmtxop -c).
const double kVisible[3] = {0.2651, 0.6701, 0.0648};
const double kCieX[3] = {0.5141, 0.3239, 0.1620};
const double kCieZ[3] = {0.0241, 0.1229, 0.8530};

// A folder of its own, removed with everything in it when the run ends (genBSDF's /tmp one).
class ScratchFolder {
  public:
    ScratchFolder() {
        std::string pattern = (fs::temp_directory_path() / "genBSDF.XXXXXX").string();
        if (!mkdtemp(pattern.data())) ErrorExit("cannot make a temporary folder");
        path_ = pattern;
    }
    ~ScratchFolder() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string operator/(const std::string &name) const { return (path_ / name).string(); }

  private:
    fs::path path_;
};

void WriteText(const std::string &path, const std::string &text) {
    std::ofstream out(path);
    out << text;
    if (!out) ErrorExit("cannot write " + path);
}

std::string Number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%e", v);
    return buf;
}

std::string Short(double v) {  // %g, as wrapBSDF and genBSDF.pl's Perl print numbers
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.15g", v);
    return buf;
}

// getbbox of the system: xmin xmax ymin ymax zmin zmax of its surfaces.
void BoundingBox(const FlatScene &flat, double dim[6]) {
    for (int k = 0; k < 3; ++k) {
        dim[2 * k] = std::numeric_limits<double>::infinity();
        dim[2 * k + 1] = -std::numeric_limits<double>::infinity();
    }
    const auto add = [&](const Vec3 &p, double r) {
        for (int k = 0; k < 3; ++k) {
            dim[2 * k] = std::min(dim[2 * k], p[k] - r);
            dim[2 * k + 1] = std::max(dim[2 * k + 1], p[k] + r);
        }
    };
    for (const Vec3 &v : flat.vertices) add(v, 0);
    for (const AnalyticShape &s : flat.shapes) {
        if (s.kind == AnalyticShape::kSource) continue;
        add(s.p0, std::max(s.r0, s.r1));
        if (s.kind == AnalyticShape::kCone || s.kind == AnalyticShape::kCylinder)
            add(s.p1, std::max(s.r0, s.r1));
    }
    if (!(dim[0] <= dim[1])) ErrorExit("genBSDF: the system has no surfaces");
}

// The two receivers (genBSDF.pl's receivers.rad): the room's side (+z) into face, the
// outside's (-z) into behind.
std::string Receivers(const std::string &face, const std::string &behind) {
    return "#@rfluxmtx h=-kf\n#@rfluxmtx u=-Y o=" + face +
           "\n\nvoid glow receiver_face\n0\n0\n4 1 1 1 0\n\n"
           "receiver_face source f_receiver\n0\n0\n4 0 0 1 180\n\n"
           "#@rfluxmtx h=+kf\n#@rfluxmtx u=-Y o=" +
           behind +
           "\n\nvoid glow receiver_behind\n0\n0\n4 1 1 1 0\n\n"
           "receiver_behind source b_receiver\n0\n0\n4 0 0 -1 180\n";
}

// The senders: forward just below the box facing -z, backward just above it facing +z.
std::string Sender(const double dim[6], bool forward) {
    std::string s = "#@rfluxmtx u=-Y ";
    s += forward ? "h=-kf\n\nvoid polygon fwd_sender\n" : "h=+kf\n\nvoid polygon bwd_sender\n";
    s += "0\n0\n12\n";
    const double z = forward ? dim[4] - kFeps : dim[5] + kFeps;
    const int order_fwd[4][2] = {{0, 2}, {0, 3}, {1, 3}, {1, 2}};
    const int order_bwd[4][2] = {{0, 2}, {1, 2}, {1, 3}, {0, 3}};
    for (const auto &xy : forward ? order_fwd : order_bwd) {
        for (double v : {dim[xy[0]], dim[xy[1]], z}) s.append("\t").append(Number(v));
        s += '\n';
    }
    return s;
}

// rmtxop -fa -t -c (spectrum) of an rfluxmtx output, then wrapBSDF -c's division by the
// projected solid angle of each (outgoing) row's patch.
std::vector<double> BsdfValues(const std::string &path, const double spectrum[3],
                               const std::string &what) {
    Matrix m = LoadMatrix(path);
    const int n = KlemsBases()[0].Size();
    if (m.rows != n || m.cols != n || m.ncomp != 3)
        ErrorExit("genBSDF: " + what + ": rfluxmtx gave " + std::to_string(m.rows) + " x " +
                  std::to_string(m.cols) + " x " + std::to_string(m.ncomp) + ", not " +
                  std::to_string(n) + " x " + std::to_string(n) + " x 3");
    const Matrix y = TransformComponents(Transpose(m), {spectrum[0], spectrum[1], spectrum[2]});
    std::vector<double> values(static_cast<size_t>(n) * n);
    for (int o = 0; o < n; ++o) {
        const double correction = 1. / KlemsBases()[0].ProjectedSolidAngle(o);
        for (int i = 0; i < n; ++i) {
            const double d = y.at(o, i, 0);
            if (d < -1e-3) ErrorExit("genBSDF: " + what + ": negative BSDF data");
            values[static_cast<size_t>(o) * n + i] = d > 0 ? d * correction : 0.;
        }
    }
    return values;
}

// wrapBSDF's field nicknames.
struct Field {
    const char *nick, *name;
    bool unit;
};
const Field kFields[] = {{"m", "Manufacturer", false},
                         {"n", "Name", false},
                         {"d", "DeviceType", false},
                         {"c", "ThermalConductivity", false},
                         {"ef", "EmissivityFront", false},
                         {"eb", "EmissivityBack", false},
                         {"tir", "TIR", false},
                         {"eo", "EffectiveOpennessFraction", false},
                         {"t", "Thickness", true},
                         {"h", "Height", true},
                         {"w", "Width", true}};

std::string XmlEscaped(const std::string &s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

const char *ComponentName(const std::string &type) {
    if (type == "tf") return "Transmission Front";
    if (type == "tb") return "Transmission Back";
    if (type == "rf") return "Reflection Front";
    if (type == "rb") return "Reflection Back";
    CHECK(false);
    return "";
}

std::string SpectrumLines(const std::string &spectrum) {
    const char *detector = spectrum == "CIE-X"   ? "ASTM E308 1931 X.dsp"
                           : spectrum == "CIE-Z" ? "ASTM E308 1931 Z.dsp"
                                                 : "ASTM E308 1931 Y.dsp";
    return "\t\t<Wavelength unit=\"Integral\">" + spectrum +
           "</Wavelength>\n\t\t<SourceSpectrum>CIE Illuminant D65 1nm.ssp</SourceSpectrum>\n"
           "\t\t<DetectorSpectrum>" +
           detector + "</DetectorSpectrum>\n";
}

}  // namespace

std::string KlemsXml(const std::vector<BsdfBlock> &blocks, const std::vector<std::string> &fields,
                     const std::string &unit, bool window6, const std::string &comment) {
    // The Material's fields in the template's order, then those assigned that it lacks.
    std::vector<std::pair<std::string, std::string>> material =
        window6 ? std::vector<std::pair<std::string, std::string>>{{"Name", ""},
                                                                   {"Manufacturer", ""},
                                                                   {"Thickness", ""},
                                                                   {"DeviceType", "Other"},
                                                                   {"ThermalConductivity", "1"},
                                                                   {"EmissivityFront", "0.9"},
                                                                   {"EmissivityBack", "0.9"},
                                                                   {"TIR", "0.1"},
                                                                   {"EffectiveOpennessFraction",
                                                                    "0.05"}}
                : std::vector<std::pair<std::string, std::string>>{
                      {"Name", "Name"}, {"Manufacturer", "Manufacturer"}, {"DeviceType", "Other"}};
    for (const std::string &list : fields) {
        for (const std::string &assignment : Split(list, ';')) {
            const std::string a = Trim(assignment);
            if (a.empty()) continue;
            const size_t eq = a.find('=');
            if (eq == std::string::npos) ErrorExit("missing '=' in assignment '" + list + "'");
            std::string name = Trim(a.substr(0, eq));
            if (name.empty() || name.find_first_of(" \t") != std::string::npos)
                ErrorExit("bad tag name in assignment '" + list + "'");
            for (const Field &f : kFields)
                if (EqualsIgnoreCase(name, f.nick) || EqualsIgnoreCase(name, f.name)) name = f.name;
            auto it = std::find_if(material.begin(), material.end(),
                                   [&](const auto &p) { return p.first == name; });
            if (it == material.end()) {
                bool known = false;
                for (const Field &f : kFields) known |= name == f.name;
                if (!known) Warning("adding tag <" + name + ">");
                it = material.insert(material.end(), {name, ""});
            }
            it->second = Trim(a.substr(eq + 1));
        }
    }
    std::string x = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n" +
                    (comment.empty() ? std::string() : "<!-- " + comment + " -->\n") +
                    "<WindowElement xmlns=\"http://windows.lbl.gov\" "
                    "xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" "
                    "xsi:schemaLocation=\"http://windows.lbl.gov/BSDF-v1.4.xsd\">\n"
                    "<WindowElementType>System</WindowElementType>\n<FileType>BSDF</FileType>\n"
                    "<Optical>\n<Layer>\n\t<Material>\n";
    for (const auto &[name, value] : material) {
        bool unit_field = false;
        for (const Field &f : kFields) unit_field |= f.unit && name == f.name;
        x += "\t\t<" + name + (unit_field ? " unit=\"" + unit + "\"" : "") + ">" +
             XmlEscaped(value) + "</" + name + ">\n";
    }
    x += "\t</Material>\n\t<DataDefinition>\n"
         "\t\t<IncidentDataStructure>Columns</IncidentDataStructure>\n"
         "\t\t<AngleBasis>\n\t\t\t<AngleBasisName>LBNL/Klems Full</AngleBasisName>\n";
    const AngleBasis &basis = KlemsBases()[0];
    for (size_t r = 0; r < basis.nphis.size(); ++r) {
        const double mid = r ? .5 * (basis.theta[r] + basis.theta[r + 1]) : 0.;
        char buf[512];
        std::snprintf(buf, sizeof buf,
                      "\t\t\t<AngleBasisBlock>\n\t\t\t\t<Theta>%g</Theta>\n"
                      "\t\t\t\t<nPhis>%d</nPhis>\n\t\t\t\t<ThetaBounds>\n"
                      "\t\t\t\t\t<LowerTheta>%g</LowerTheta>\n"
                      "\t\t\t\t\t<UpperTheta>%g</UpperTheta>\n"
                      "\t\t\t\t</ThetaBounds>\n\t\t\t</AngleBasisBlock>\n",
                      mid, basis.nphis[r], basis.theta[r], basis.theta[r + 1]);
        x += buf;
    }
    x += "\t\t</AngleBasis>\n\t</DataDefinition>\n";
    const int n = basis.Size();
    for (const BsdfBlock &b : blocks) {
        CHECK(b.values.size() == static_cast<size_t>(n) * n);
        x += "\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>\n" +
             SpectrumLines(b.spectrum) +
             "\t\t<WavelengthDataBlock>\n\t\t\t<WavelengthDataDirection>" + ComponentName(b.type) +
             "</WavelengthDataDirection>\n"
             "\t\t\t<ColumnAngleBasis>LBNL/Klems Full</ColumnAngleBasis>\n"
             "\t\t\t<RowAngleBasis>LBNL/Klems Full</RowAngleBasis>\n"
             "\t\t\t<ScatteringDataType>BTDF</ScatteringDataType>\n"
             "\t\t\t<ScatteringData>\n";
        char buf[32];
        for (int o = 0; o < n; ++o) {
            for (int i = 0; i < n; ++i) {
                std::snprintf(buf, sizeof buf, " %.3e", b.values[static_cast<size_t>(o) * n + i]);
                x += buf;
            }
            x += '\n';
        }
        x += "\t\t\t</ScatteringData>\n\t\t</WavelengthDataBlock>\n\t</WavelengthData>\n";
    }
    return x + "</Layer>\n</Optical>\n</WindowElement>\n";
}

GenBsdfOptions ParseGenBsdfOptions(const std::vector<std::string> &args) {
    GenBsdfOptions o;
    const std::string usage =
        "usage: genBSDF [-n Nproc][-c Nsamp][-W][-r \"ropts\"][-s \"x=string;y=string\"][-dim "
        "xmin xmax ymin ymax zmin zmax][{+|-}C][{+|-}a][{+|-}f][{+|-}b][{+|-}geom units] "
        "[input ..]";
    size_t i = 1;
    const auto value = [&](const std::string &option) -> const std::string & {
        if (i + 1 >= args.size()) ErrorExit(option + " needs a value; " + usage);
        return args[++i];
    };
    const auto number = [&](const std::string &option, const std::string &text) {
        double v = 0;
        if (!ParseNumber(text, &v) || !std::isfinite(v))
            ErrorExit(option + " " + text + ": not a number");
        return v;
    };
    for (; i < args.size(); ++i) {
        const std::string &a = args[i];
        if (a.size() < 2 || (a[0] != '-' && a[0] != '+') || a == "-") break;
        const bool plus = a[0] == '+';
        const std::string name = a.substr(1);
        if (a == "-seed" || IsEngineOption(a)) {  // ours, for rfluxmtx-gpu (before -b...)
            o.engine_options.push_back(a);
            o.engine_options.push_back(value(a));
        } else if (name[0] == 'm') {
            if (plus) ErrorExit("+mgf: MGF input is not supported; give RADIANCE scene files");
        } else if (a == "-r") {
            for (const std::string &w : SplitWords(value(a))) o.rfluxmtx_options.push_back(w);
        } else if (name[0] == 'g') {
            o.unit = value(a);
            static const char *const units[] = {"meter", "foot", "inch", "centimeter",
                                                "millimeter"};
            bool legal = false;
            for (const char *u : units) legal |= EqualsIgnoreCase(o.unit, u);
            if (!legal)
                ErrorExit("Illegal geometry unit '" + o.unit +
                          "': must be meter, foot, inch, centimeter, or millimeter");
            if (plus) Warning("+geom: the system's geometry (MGF) is not written into the XML");
        } else if (name[0] == 'C') {
            o.colour = plus;
        } else if (name[0] == 'a') {
            // reciprocity averaging: genBSDF applies it to tensor trees only
        } else if (name[0] == 'f') {
            o.forward = plus;
        } else if (name[0] == 'b') {
            o.backward = plus;
        } else if (a == "-t3" || a == "-t4") {
            ErrorExit(a + ": tensor-tree BSDFs are not supported (Klems full only)");
        } else if (a == "-t") {  // the tensor tree's culling percentage: nothing to cull here
            if (number(a, value(a)) >= 100)
                ErrorExit("Illegal -t culling percentage, must be < 100");
        } else if (a == "-s") {
            o.fields.push_back(value(a));
        } else if (a == "-W") {
            o.window6 = true;
        } else if (a == "-c") {
            const double c = number(a, value(a));
            if (c < 1 || c > 1e7) ErrorExit("-c " + args[i] + ": samples from 1 to 1e7");
            o.samples = static_cast<int>(c);
        } else if (a == "-n") {
            const double n = number(a, value(a));
            if (n < 1 || n > 1024) ErrorExit("-n " + args[i] + ": processes from 1 to 1024");
            o.processes = static_cast<int>(n);
        } else if (a.rfind("-d", 0) == 0) {
            if (i + 6 >= args.size()) ErrorExit(a + " needs six numbers; " + usage);
            for (int k = 0; k < 6; ++k) o.dim[k] = number(a, args[++i]);
            if (!(o.dim[0] < o.dim[1] && o.dim[2] < o.dim[3] && o.dim[4] <= o.dim[5]))
                ErrorExit(a + ": need xmin < xmax, ymin < ymax, zmin <= zmax");
            o.has_dim = true;
        } else {
            ErrorExit("unknown option '" + a + "'; " + usage);
        }
    }
    for (; i < args.size(); ++i) o.inputs.push_back(args[i]);
    o.command_line = "genBSDF";
    for (size_t k = 1; k < args.size(); ++k) o.command_line += " " + args[k];
    if (!o.forward && !o.backward) ErrorExit("Must have at least one of +forward or +backward");
    return o;
}

std::string GenBsdf(const GenBsdfOptions &o, const std::string &program) {
    ScratchFolder tmp;
    // The system, as one file (genBSDF's xform -e), the standard input where none is named.
    std::vector<std::string> system = o.inputs;
    if (system.empty() || (system.size() == 1 && system[0] == "-")) {
        const std::string text((std::istreambuf_iterator<char>(std::cin)),
                               std::istreambuf_iterator<char>());
        WriteText(tmp / "device.rad", text);
        system = {tmp / "device.rad"};
    }
    double dim[6];
    if (o.has_dim) {
        std::copy(o.dim, o.dim + 6, dim);
    } else {
        Scene scene;
        SceneReader reader(&scene);
        for (const std::string &f : system) reader.ReadFile(f);
        BoundingBox(Flatten(std::move(scene)), dim);
    }
    if (!(dim[1] > dim[0] && dim[3] > dim[2]))
        ErrorExit("the system's box has no width or height (x " + Short(dim[0]) + " to " +
                  Short(dim[1]) + ", y " + Short(dim[2]) + " to " + Short(dim[3]) + "): give -dim");
    if (dim[4] >= 0) ErrorExit("Device entirely inside room!");
    if (dim[5] > 1e-5)
        Warning("Device extends into room");
    else if (dim[5] * dim[5] > .01 * (dim[1] - dim[0]) * (dim[3] - dim[2]))
        Warning("Device far behind Z==0 plane");

    // genBSDF's grid of sender samples: nx x ny, at least -c.
    const int nx =
        static_cast<int>(std::sqrt(o.samples * (dim[1] - dim[0]) / (dim[3] - dim[2])) + 1);
    const int ny = static_cast<int>(o.samples / nx + 1);
    const int samples = nx * ny;

    const std::string face = tmp / "face.dat", behind = tmp / "behind.dat";
    WriteText(tmp / "receivers.rad", Receivers(face, behind));
    std::vector<BsdfBlock> blocks;
    const auto direction = [&](bool forward) {
        const std::string sender = tmp / (forward ? "fsender.rad" : "bsender.rad");
        WriteText(sender, Sender(dim, forward));
        std::vector<std::string> args = {program + " (rfluxmtx)"};
        args.insert(args.end(), std::begin(kRfluxmtxDefaults), std::end(kRfluxmtxDefaults));
        args.insert(args.end(), o.rfluxmtx_options.begin(), o.rfluxmtx_options.end());
        if (o.processes > 0) args.insert(args.end(), {"-n", std::to_string(o.processes)});
        args.insert(args.end(), {"-c", std::to_string(samples)});
        args.insert(args.end(), o.engine_options.begin(), o.engine_options.end());
        args.insert(args.end(), {"-fd", sender, tmp / "receivers.rad"});
        args.insert(args.end(), system.begin(), system.end());
        RunRfluxmtx(args);
        // Transmission reaches the far side's receiver, reflection the near side's.
        const std::string &trans = forward ? face : behind, &refl = forward ? behind : face;
        const std::string t = forward ? "tf" : "tb", r = forward ? "rf" : "rb";
        const auto add = [&](const std::string &type, const std::string &path) {
            blocks.push_back({type, "Visible", BsdfValues(path, kVisible, type)});
            if (o.colour) {
                blocks.push_back({type, "CIE-X", BsdfValues(path, kCieX, type)});
                blocks.push_back({type, "CIE-Z", BsdfValues(path, kCieZ, type)});
            }
        };
        add(t, trans);
        add(r, refl);
    };
    if (o.backward) direction(false);
    if (o.forward) direction(true);
    std::vector<std::string> fields = o.fields;
    fields.push_back("t=" + Short(-dim[4]) + ";w=" + Short(dim[1] - dim[0]) +
                     ";h=" + Short(dim[3] - dim[2]));
    // XML comments may not hold "--" (a file named a--b.rad)
    std::string comment = "Created by: " + o.command_line;
    for (size_t at; (at = comment.find("--")) != std::string::npos;) comment.replace(at, 2, "- -");
    return KlemsXml(blocks, fields, o.unit, o.window6, comment);
}

}  // namespace dayflux
