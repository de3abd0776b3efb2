#include "rcontrib/outputs.h"

#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "matrix/header.h"
#include "matrix/rgbe.h"
#include "matrix/writer.h"
#include "util/errors.h"
#include "util/strings.h"

namespace dayflux {

namespace fs = std::filesystem;

// One output: the standard output or a file (command) that -o names, with the columns (bins)
// that go there in order.
struct RcontribOutputs::Stream {
    std::string name;
    std::string modifier;
    int bin = 0;
    int flags = 0;
    bool standard_error = false;  // the -se output
    std::vector<int> columns;
    std::unique_ptr<OutputFile> file;
    std::string recover_from;  // -r: the partial file of a stopped run, or the output itself
    size_t prefix_bytes = 0;   // -r: the existing file's header (and resolution line)
};

std::string OutputName(const std::string &spec, const std::string &mod, int bin, int *flags) {
    size_t mpos = std::string::npos, bpos = std::string::npos;
    for (size_t i = 0; i < spec.size(); ++i) {
        if (spec[i] != '%') continue;
        do ++i;
        while (i < spec.size() && std::isdigit(static_cast<unsigned char>(spec[i])));
        const char c = i < spec.size() ? spec[i] : '\0';
        if (c == '%') continue;
        if (c == 's' && mpos == std::string::npos)
            mpos = i;
        else if (std::strchr("dioxX", c) && c && bpos == std::string::npos)
            bpos = i;
        else
            ErrorExit("bad output format '" + spec + "'");
    }
    *flags =
        (mpos != std::string::npos ? kByModifier : 0) | (bpos != std::string::npos ? kByBin : 0);
    // The spec was checked above: only digits between % and the conversion.
    std::vector<char> buf(spec.size() + mod.size() + 64);
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#pragma GCC diagnostic ignored "-Wformat-security"
    if (*flags == (kByModifier | kByBin) && mpos < bpos)
        std::snprintf(buf.data(), buf.size(), spec.c_str(), mod.c_str(), bin);
    else if (*flags == (kByModifier | kByBin))
        std::snprintf(buf.data(), buf.size(), spec.c_str(), bin, mod.c_str());
    else if (*flags == kByModifier)
        std::snprintf(buf.data(), buf.size(), spec.c_str(), mod.c_str());
    else if (*flags == kByBin)
        std::snprintf(buf.data(), buf.size(), spec.c_str(), bin);
    else if (*flags == 0)
        std::snprintf(buf.data(), buf.size(), "%s", spec.c_str());
#pragma GCC diagnostic pop
    return buf.data();
}

namespace {

size_t RecordBytes(const RcontribOptions &o, size_t columns) {
    return o.out == DataFormat::RGBE ? 4 * columns
                                     : (o.out == DataFormat::Float ? 12 : 24) * columns;
}

// Copies the first `bytes` of file `name` to out, in pieces (a recovered output may be large).
void CopyPrefix(const std::string &name, size_t bytes, OutputFile *out) {
    std::ifstream f(name, std::ios::binary);
    std::vector<char> piece(size_t(1) << 22);
    while (bytes > 0) {
        const size_t n = std::min(bytes, piece.size());
        if (!f.read(piece.data(), static_cast<std::streamsize>(n)))
            ErrorExit("cannot read '" + name + "' to recover it");
        out->Write(piece.data(), n);
        bytes -= n;
    }
}

// A file per modifier (-o %s with a sun per modifier) can mean thousands open at once: up to
// the hard limit, where RADIANCE stops at the soft one (1024 on Debian).
void AllowOpenFiles(size_t n) {
    struct rlimit files;
    if (getrlimit(RLIMIT_NOFILE, &files) == 0 && files.rlim_cur < files.rlim_max &&
        n + 64 > files.rlim_cur) {
        files.rlim_cur = files.rlim_max;
        setrlimit(RLIMIT_NOFILE, &files);
    }
}

}  // namespace

RcontribOutputs::RcontribOutputs(const RcontribOptions &o, int ncols,
                                 std::vector<std::string> header_args,
                                 const std::string &octree_header, const std::string &label)
    : o_(o) {
    // In the order RADIANCE opens them: by modifier, then bin; the modifiers without -o go to
    // the standard output together.
    std::map<std::string, size_t> named;
    for (const ModifierSpec &m : o.modifiers)
        for (int b = 0; b < m.tracked.nbins; ++b) {
            int flags = 0;
            const std::string name =
                m.output.empty() ? "-" : OutputName(m.output, m.tracked.name, b, &flags);
            auto [it, added] = named.emplace(name, streams_.size());
            if (added) {
                Stream &s = streams_.emplace_back();
                s.name = name, s.modifier = m.tracked.name, s.bin = b, s.flags = flags;
            }
            streams_[it->second].columns.push_back(m.tracked.first_column + b);
        }
    AllowOpenFiles(streams_.size());
    if (!o.stderr_file.empty()) {
        Stream &se = streams_.emplace_back();
        se.name = o.stderr_file;
        se.standard_error = true;
        for (int c = 0; c < ncols; ++c) se.columns.push_back(c);
    }
    // One file under two names (-se and -o, "./a" and "a") would be written twice at once.
    std::map<fs::path, std::string> files;
    for (const Stream &s : streams_) {
        if (s.name == "-" || s.name[0] == '!') continue;
        std::error_code ec;
        const fs::path key = fs::weakly_canonical(fs::absolute(s.name), ec);
        const auto [it, added] = files.emplace(ec ? fs::path(s.name) : key, s.name);
        if (!added)
            ErrorExit("'" + s.name + "' and '" + it->second + "' name the same output file");
    }
    // -r: the complete records every output already has, kept (header and all) in front of
    // the rest.
    recovered_ = o.recover ? RecoverableRecords() : 0;
    for (Stream &s : streams_) Open(s, header_args, octree_header, label);
}

RcontribOutputs::~RcontribOutputs() = default;

void RcontribOutputs::Open(Stream &s, const std::vector<std::string> &header_args,
                           const std::string &octree_header, const std::string &label) {
    const RcontribOptions &o = o_;
    const bool is_file = s.name != "-" && s.name[0] != '!';
    if (is_file && !o.recover && !o.force_open) {
        if (fs::exists(s.name))
            ErrorExit("cannot open '" + s.name + "' for writing: file exists (use -fo+)");
        // A partial file without a complete record (cut in its header, another format) is
        // nothing to lose.
        size_t prefix = 0;
        const std::string partial = OutputFile::PartialName(s.name);
        bool holds_records = false;
        try {
            holds_records = fs::exists(partial) && RecordsIn(partial, s, true, &prefix) > 0;
        } catch (const UserError &) {
        }
        if (holds_records)
            ErrorExit("'" + OutputFile::PartialName(s.name) +
                      "' holds the records of a run that stopped early: continue it with -r, "
                      "or start over with -fo+");
    }
    const int reclen = static_cast<int>(s.columns.size());
    if (recovered_ > 0) {
        const size_t kept = s.prefix_bytes + recovered_ * RecordBytes(o, s.columns.size());
        if (s.recover_from == s.name) {
            s.file = std::make_unique<OutputFile>(s.name);
            CopyPrefix(s.name, kept, s.file.get());
        } else {
            s.file = std::make_unique<OutputFile>(s.name, kept);
        }
        return;
    }
    s.file = std::make_unique<OutputFile>(s.name);
    if (o.header) {
        std::vector<std::string> args = header_args;
        std::vector<char *> av;
        for (std::string &a : args) av.push_back(a.data());
        std::string h = HeaderStart(static_cast<int>(av.size()), av.data());
        h.insert(h.find('\n') + 1, octree_header);
        h += "SOFTWARE= dayflux rcontrib-gpu (" + label + ")\n" + DateLines() + "NCOMP=3\n";
        if (s.name != "-" && ((s.flags & kByModifier) || reclen == 1))
            h += "MODIFIER=" + s.modifier + "\n";
        if (s.flags & kByBin) h += "BIN=" + std::to_string(s.bin) + "\n";
        if (o.yres > 0) h += "NROWS=" + std::to_string(o.yres * std::max(o.xres, 1)) + "\n";
        if (o.xres <= 0 || reclen > 1) h += "NCOLS=" + std::to_string(reclen) + "\n";
        if (o.out == DataFormat::Float || o.out == DataFormat::Double)
            h += NativeBigEndian() ? "BigEndian=1\n" : "BigEndian=0\n";
        h += FormatLine(o.out) + "\n";
        s.file->Write(h);
    }
    if (reclen == 1 && o.xres > 0 && o.yres > 0) s.file->Write(ResolutionLine(o.xres, o.yres));
}

// The complete records in file (an output of stream s), and the bytes before them in *prefix;
// -1 where it has none to give: missing, empty, or (a partial file) cut inside its header.
long RcontribOutputs::RecordsIn(const std::string &file, const Stream &s, bool partial,
                                size_t *prefix) const {
    const RcontribOptions &o = o_;
    std::error_code ec;
    const auto size = fs::file_size(file, ec);
    if (ec || size == 0) return -1;
    std::ifstream f(file, std::ios::binary);
    std::string head(std::min<uintmax_t>(size, 1 << 16), '\0');
    f.read(head.data(), static_cast<std::streamsize>(head.size()));
    size_t body = 0;
    if (o.header) {
        const size_t end = head.find("\n\n");
        if (end == std::string::npos && partial) return -1;
        if (head.rfind("#?RADIANCE", 0) != 0 || end == std::string::npos ||
            head.substr(0, end + 1).find(FormatLine(o.out)) == std::string::npos)
            ErrorExit("format mismatch for '" + file + "'");
        body = end + 2;
    }
    if (s.columns.size() == 1 && o.xres > 0 && o.yres > 0) {
        const size_t eol = head.find('\n', body);
        if (eol == std::string::npos && partial) return -1;
        if (eol == std::string::npos ||
            head.substr(body, eol + 1 - body) != ResolutionLine(o.xres, o.yres))
            ErrorExit("resolution mismatch for '" + file + "'");
        body = eol + 1;
    }
    *prefix = body;
    return static_cast<long>((size - body) / RecordBytes(o, s.columns.size()));
}

// recover_output(): the number of complete records in every output (0 if there is nothing to
// recover), after checking that they are files of the format asked for. Each output continues
// its partial file (a stopped run's, newer than the output) where that holds a complete record,
// else the output itself, as RADIANCE's -r does. Sets recover_from and prefix_bytes.
long RcontribOutputs::RecoverableRecords() {
    const RcontribOptions &o = o_;
    if (o.out == DataFormat::Ascii) ErrorExit("cannot recover ASCII output");
    if (o.accumulate <= 0) ErrorExit("cannot recover with -c 0 (one record of all rays)");
    long last = -1;
    for (Stream &s : streams_) {
        if (s.name == "-") ErrorExit("cannot recover from stdout");
        if (s.name[0] == '!') ErrorExit("cannot recover from command");
        if (ResolveOutput(s.name).direct)
            ErrorExit("cannot recover '" + s.name + "': it is not a regular file");
        const std::string partial = OutputFile::PartialName(s.name);
        long n = RecordsIn(partial, s, true, &s.prefix_bytes);
        s.recover_from = partial;
        if (n <= 0) {
            n = RecordsIn(s.name, s, false, &s.prefix_bytes);
            s.recover_from = s.name;
        }
        if (n < 0) {
            if (!fs::exists(s.name) && !fs::exists(partial))
                Warning("missing recover file '" + s.name + "'");
            Warning("no previous data to recover");
            return 0;
        }
        if (last < 0 || n < last) last = n;
    }
    if (last == 0) Warning("no previous data to recover");
    return std::max(last, 0L);
}

void RcontribOutputs::Write(const std::vector<double> &values,
                            const std::vector<double> &standard_errors) {
    for (Stream &s : streams_) {
        const std::vector<double> &v = s.standard_error ? standard_errors : values;
        text_.clear();
        if (o_.out == DataFormat::Ascii) {
            for (int c : s.columns)
                for (int k = 0; k < 3; ++k) {
                    AppendScientific(&text_, v[3 * c + k], 6);
                    text_ += '\t';
                }
            text_ += '\n';
        } else if (o_.out == DataFormat::RGBE) {
            // RGBE as rcontrib writes it: one flat 4-byte colour per entry, so a one-column
            // output with -x and -y is a picture.
            for (int c : s.columns) {
                const Colr colr = ToColr(v[3 * c], v[3 * c + 1], v[3 * c + 2]);
                text_.append(reinterpret_cast<const char *>(colr.data()), 4);
            }
        } else {
            part_.clear();
            for (int c : s.columns) part_.insert(part_.end(), &v[3 * c], &v[3 * c + 3]);
            RowFormatter(o_.out, static_cast<int>(s.columns.size()), 3)
                .Append(part_.data(), &text_);
        }
        s.file->Write(text_);
    }
    ++written_;
}

void RcontribOutputs::Flush() {
    for (Stream &s : streams_) std::fflush(s.file->Stream());
}

void RcontribOutputs::Commit() {
    // Every output flushed before any is renamed: a full disk leaves them all partial, for -r.
    for (Stream &s : streams_)
        if (std::fflush(s.file->Stream()) != 0)
            ErrorExit("error writing to '" + s.file->Name() + "': " + std::strerror(errno));
    for (Stream &s : streams_) s.file->Commit();
}

std::string RcontribOutputs::KeepPartial() {
    // Kept only where -r can continue them: binary records of -c rays, all in files, at least one
    // written. Otherwise the partial files go (those this run continued stay, as they were).
    bool recoverable = o_.out != DataFormat::Ascii && o_.accumulate > 0;
    for (const Stream &s : streams_) recoverable = recoverable && s.file && s.file->IsFile();
    const long records = recovered_ + written_;
    bool flushed = true;
    std::string kept;
    for (Stream &s : streams_) {
        if (!s.file || (s.file->IsFile() && !(recoverable && records > 0))) continue;
        flushed = s.file->KeepPartial() && flushed;  // the standard output: what was written
        if (s.file->IsFile())
            kept += (kept.empty() ? "'" : ", '") + OutputFile::PartialName(s.name) + "'";
    }
    if (kept.empty()) return "";
    // After a write error the files hold fewer records than were written (-r counts them).
    const std::string what =
        flushed ? std::to_string(records) + " complete record" + (records == 1 ? "" : "s")
                : "the records written";
    return what + " kept in " + kept + ": the same command with -r continues the run";
}

}  // namespace dayflux
