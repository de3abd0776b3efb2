// rcalc: RADIANCE's record calculator on our calcomp (src/cal): each input record's columns are
// $1, $2, ...; "$N = e;" definitions (-e, -f) make the output columns, or an output template
// (-o) with ${expression} and $(string) fields does; cond, recno and outno as in RADIANCE;
// ascii, float and double input and output; input templates (-i) read records as RADIANCE's do.
// Output byte for byte as RADIANCE 5.4a's. Not yet: the in() function.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cal/calcomp.h"
#include "util/errors.h"
#include "util/raypath.h"

namespace dayflux {
namespace {

constexpr size_t kRecordBytes = 16384;  // INBSIZ: a longer line is read as several records
constexpr int kCachedColumns = 32;      // MAXCOL

struct Options {
    bool blanks_equal = true;          // -b toggles: runs of blanks separate columns once
    bool ignore_eol = false;           // -l
    char separator = '\t';             // -tS
    bool no_input = false;             // -n
    long in_count = 0, out_count = 0;  // -in, -on
    char in_type = 'a', out_type = 'a';
    int binary_columns = 0;  // -id N, -if N
    bool unbuffered = false;
    std::string out_format;                      // -o
    std::string in_format;                       // -i
    bool passive = false;                        // -p: input no template matches is copied out
    std::map<std::string, std::string> strings;  // -s name=value
};

[[noreturn]] void Usage(const char *prog) {
    std::fprintf(stderr,
                 "Usage: %s [-b][-l][-n][-p][-w][-u][-tS][-s svar=sval][-e expr][-f source]"
                 "[-i infmt][-o outfmt] [file]\n",
                 prog);
    std::exit(1);
}

// The columns of the record being processed ($N), read as RADIANCE's chanvalue() reads them.
class RecordChannels : public cal::Channels {
  public:
    explicit RecordChannels(const Options &o) : o_(o) {}
    void SetText(const std::string &line) {
        text_ = line;
        flags_ = 0;
    }
    void SetBinary(std::vector<double> values) { binary_ = std::move(values); }
    double Value(int n) const override {
        if (o_.no_input || !o_.in_format.empty()) ErrorExit("no column input");
        if (n < 1) ErrorExit("illegal channel number");
        if (o_.binary_columns) return n <= static_cast<int>(binary_.size()) ? binary_[n - 1] : 0;
        if (n <= kCachedColumns && (flags_ >> (n - 1) & 1)) return cached_[n - 1];
        const char *cp = text_.c_str();
        const bool blank =
            o_.blanks_equal && std::isspace(static_cast<unsigned char>(o_.separator));
        for (int i = 1; i < n; ++i) {
            if (blank) {
                while (std::isspace(static_cast<unsigned char>(*cp))) ++cp;
                while (*cp && !std::isspace(static_cast<unsigned char>(*cp))) ++cp;
            } else {
                while (*cp && *cp++ != o_.separator) {
                }
            }
        }
        while (std::isspace(static_cast<unsigned char>(*cp))) ++cp;
        const double v = std::atof(cp);
        if (n <= kCachedColumns) {
            flags_ |= 1u << (n - 1);
            cached_[n - 1] = v;
        }
        return v;
    }

    // in(0): the record's columns, counted as RADIANCE's l_in() counts them (none with -i or
    // -n, where the record is not columns).
    int Count() const override {
        if (o_.no_input || !o_.in_format.empty()) return 0;
        if (o_.binary_columns) return o_.binary_columns;
        const bool blank =
            o_.blanks_equal && std::isspace(static_cast<unsigned char>(o_.separator));
        int n = 0;
        for (const char *cp = text_.c_str(); *cp;) {
            if (blank) {
                while (std::isspace(static_cast<unsigned char>(*cp))) ++cp;
                n += *cp != '\0';
                while (*cp && !std::isspace(static_cast<unsigned char>(*cp))) ++cp;
            } else {
                n += *cp != '\n';
                while (*cp && *cp++ != o_.separator) {
                }
            }
        }
        return n;
    }

  private:
    const Options &o_;
    std::string text_;
    std::vector<double> binary_;
    mutable uint32_t flags_ = 0;
    mutable double cached_[kCachedColumns] = {};
};

// One piece of an output template (readfield()): literal text, a string variable $(name) or an
// expression ${e}, with the width the piece took in the template.
struct Field {
    enum Kind { kLiteral, kString, kNumber } kind;
    std::string text;
    int width;
    cal::Expression expression;
};

// readfmt(): a template's fields, an output one's expressions compiled (cx), an input one's
// variables named.
std::vector<Field> ReadTemplate(const std::string &spec, bool ignore_eol, const cal::Context *cx) {
    std::string text = spec;
    if (spec.find('$') == std::string::npos) {  // a file holding the template
        std::ifstream f(spec, std::ios::binary);
        std::ostringstream s;
        if (!f || !(s << f.rdbuf())) ErrorExit(spec + ": cannot open");
        text = s.str();
        if (text.empty()) ErrorExit(spec + ": empty file");
    }
    std::vector<Field> fields;
    size_t p = 0;
    const auto read_field = [&](const std::string &t, size_t *pos) {
        Field f{Field::kLiteral, "", 0, {}};
        int type = -1;
        while (*pos < t.size()) {
            ++f.width;
            const char c = t[*pos];
            if (type < 0) {
                if (c == '$') {
                    ++*pos;
                    ++f.width;
                    if (*pos < t.size() && (t[*pos] == '{' || t[*pos] == '(')) {
                        type = t[*pos] == '{' ? Field::kNumber : Field::kString;
                        ++*pos;
                        continue;
                    }
                    if (*pos >= t.size() || t[*pos] != '$') ErrorExit("format error");
                    --f.width;
                }
                type = Field::kLiteral;
                f.text += t[(*pos)++];
                continue;
            }
            if (type == Field::kLiteral) {
                if (c == '$') {
                    --f.width;
                    break;
                }
                f.text += t[(*pos)++];
                continue;
            }
            const char close = type == Field::kNumber ? '}' : ')';
            ++*pos;
            if (c == close) break;
            if (!std::isspace(static_cast<unsigned char>(c))) f.text += c;
        }
        f.kind = static_cast<Field::Kind>(type < 0 ? 0 : type);
        return type < 0 ? std::optional<Field>() : std::optional<Field>(std::move(f));
    };
    std::string rest = text;
    bool added_newline = false;
    while (true) {
        std::optional<Field> f = read_field(rest, &p);
        if (!f) break;
        if (f->kind == Field::kNumber && cx) f->expression = cx->Compile(f->text, FileLoc{"-o", 0});
        fields.push_back(std::move(*f));
        // A template not ending in a newline gets one (unless -l).
        if (!ignore_eol && !added_newline && p >= rest.size() && rest.back() != '\n') {
            rest = "\n";
            p = 0;
            added_newline = true;
        }
    }
    return fields;
}

// String variables ($(name) in templates): their values, reset to -s's presets at each record.
struct StringVariable {
    std::optional<std::string> value, preset;
};
using StringVariables = std::map<std::string, StringVariable>;

bool IsNumberChar(int c) {
    return std::isdigit(c) || c == '-' || c == '.' || c == '+' || c == 'e' || c == 'E';
}

// getrec(): records matched against an input template, read through RADIANCE's circular
// lookahead buffer (a record that does not match is retried from the next character; -p copies
// the characters skipped so).
class TemplateInput {
  public:
    TemplateInput(const Options &o, std::vector<Field> fields, cal::Context &cx,
                  StringVariables *strings)
        : o_(o), fields_(std::move(fields)), cx_(cx), strings_(*strings), buf_(kRecordBytes) {
        // nbsynch(): blanks that begin the template match nothing
        if (o.blanks_equal && !fields_.empty() && fields_[0].kind == Field::kLiteral) {
            std::string &t = fields_[0].text;
            t.erase(0,
                    std::min(t.find_first_not_of(o.ignore_eol ? " \t\n\r\f\v" : " \t"), t.size()));
            if (t.empty()) fields_.erase(fields_.begin());
        }
    }

    void Start(std::FILE *f) {  // initinp()
        fin_ = f;
        beg_ = end_ = 0;
        pos_ = -1;
        chr_ = '\0';
        Scan();
    }

    bool Next() {
        while (chr_ != EOF) {
            if (o_.blanks_equal) {
                while (Blank(chr_)) Reset();
                if (chr_ == EOF) return false;
            }
            const bool eat_line = !o_.ignore_eol && chr_ != '\n';
            Clear();
            size_t k = 0;
            while (k < fields_.size() && Match(k)) ++k;
            // A record that took no input (a template of numbers where there are none, with
            // -l) would match forever (RADIANCE's hangs): it is a mismatch.
            if (k == fields_.size() && pos_ != beg_) {
                beg_ = pos_;  // advinp()
                return true;
            }
            Reset();
            if (eat_line) {
                while (chr_ != '\n') {
                    if (chr_ == EOF) return false;
                    Reset();
                }
                Reset();
            }
        }
        return false;
    }

  private:
    bool Blank(int c) const { return o_.ignore_eol ? std::isspace(c) != 0 : c == ' ' || c == '\t'; }
    void Scan() {  // scaninp()
        if (chr_ == EOF) return;
        if (++pos_ >= static_cast<long>(buf_.size())) pos_ = 0;
        if (pos_ == end_) {
            if ((chr_ = std::getc(fin_)) != EOF) {
                buf_[end_] = static_cast<char>(chr_);
                if (++end_ >= static_cast<long>(buf_.size())) end_ = 0;
                if (end_ == beg_) beg_ = -1;
            }
        } else {
            chr_ = static_cast<unsigned char>(buf_[pos_]);
        }
    }
    void Reset() {  // resetinp()
        if (beg_ < 0) beg_ = end_;
        pos_ = beg_;
        chr_ = static_cast<unsigned char>(buf_[pos_]);
        if (o_.passive) std::putchar(chr_);
        if (++beg_ >= static_cast<long>(buf_.size())) beg_ = 0;
        Scan();
    }
    void Clear() {  // clearrec()
        numbers_.clear();
        for (const Field &f : fields_)
            if (f.kind == Field::kString) {
                StringVariable &v = strings_[f.text];
                v.value = v.preset;
            }
    }
    int Delimiter(size_t k) const {
        return k + 1 < fields_.size() && fields_[k + 1].kind == Field::kLiteral
                   ? static_cast<unsigned char>(fields_[k + 1].text[0])
                   : EOF;
    }
    bool InWord(int delim, size_t length, const Field &f) const {
        if (o_.blanks_equal && delim != EOF) return Blank(delim) ? !Blank(chr_) : chr_ != delim;
        return static_cast<int>(length) < f.width;
    }
    bool Match(size_t k) {  // getfield()
        const Field &f = fields_[k];
        constexpr size_t kMaxWord = 4095;  // RMAXWORD
        std::string word;
        if (f.kind == Field::kLiteral) {
            for (size_t c = 0; c < f.text.size();) {
                if (o_.blanks_equal && Blank(static_cast<unsigned char>(f.text[c]))) {
                    if (!Blank(chr_)) return false;
                    while (c < f.text.size() && Blank(static_cast<unsigned char>(f.text[c]))) ++c;
                    do Scan();
                    while (Blank(chr_));
                } else if (static_cast<unsigned char>(f.text[c]) == chr_) {
                    ++c;
                    Scan();
                } else {
                    return false;
                }
            }
            return true;
        }
        const int delim = Delimiter(k);
        if (f.kind == Field::kString) {
            bool in = true;
            while (in && word.size() < kMaxWord) {
                in = chr_ != EOF && chr_ != '\n' && InWord(delim, word.size(), f);
                if (in) {
                    word.push_back(static_cast<char>(chr_));
                    Scan();
                }
            }
            StringVariable &v = strings_[f.text];
            if (!v.value) {
                v.value = word;
                return true;
            }
            return *v.value == word;
        }
        long number_at = -1;
        bool in = true;
        while (in && word.size() < kMaxWord) {
            in = ((number_at < 0 && Blank(chr_)) || IsNumberChar(chr_)) &&
                 InWord(delim, word.size(), f);
            if (in) {
                if (number_at < 0 && !Blank(chr_)) number_at = static_cast<long>(word.size());
                word.push_back(static_cast<char>(chr_));
                Scan();
            }
        }
        double d = number_at < 0 ? 0. : std::atof(word.c_str() + number_at);
        const auto it = numbers_.find(f.text);
        if (it == numbers_.end()) {
            numbers_[f.text] = d;
            cx_.Set(f.text, d);
            return true;
        }
        d = (it->second - d) / (d == 0. ? 1. : d);
        return !(d > .001 || d < -.001);
    }

    const Options &o_;
    std::vector<Field> fields_;
    cal::Context &cx_;
    StringVariables &strings_;
    std::map<std::string, double> numbers_;  // the record's variables set so far
    std::vector<char> buf_;
    long beg_ = 0, pos_ = -1, end_ = 0;
    int chr_ = 0;
    std::FILE *fin_ = nullptr;
};

class Calculator {
  public:
    Calculator(const Options &o, cal::Context &cx)
        : o_(o), cx_(cx), channels_(o), outputs_(cx.OutputChannels()) {
        for (const auto &[name, value] : o.strings) strings_[name] = {value, value};
        if (!o.out_format.empty()) template_ = ReadTemplate(o.out_format, o.ignore_eol, &cx);
        if (!o.in_format.empty())
            input_.emplace(o, ReadTemplate(o.in_format, o.ignore_eol, nullptr), cx, &strings_);
        const int cond = cx.SymbolIndex("cond");
        conditional_ = cond >= 0 && cx.Find(cond);
        if (conditional_) cond_ = cx.Compile("cond", FileLoc{"cond", 0});
        set_recno_ = cx.SymbolIndex("recno") >= 0;
        set_outno_ = cx.SymbolIndex("outno") >= 0;
    }

    void NoInput() { PutOut(); }

    void Process(std::FILE *in) {
        long records = 0, outputs = 0;
        if (input_) input_->Start(in);
        std::string line;
        while (Next(in, &line)) {
            ++records;
            if (set_recno_) cx_.Set("recno", static_cast<double>(records));
            if (set_outno_) cx_.Set("outno", static_cast<double>(outputs + 1));
            if (!conditional_ || cond_.Evaluate(cx_, &channels_) > 0.0) {
                PutOut();
                ++outputs;
            }
            if (o_.in_count && records >= o_.in_count) break;
            if (o_.out_count && outputs >= o_.out_count) break;
        }
    }

  private:
    bool Next(std::FILE *in, std::string *line) {
        if (input_) return input_->Next();
        if (o_.in_type != 'a') {
            const bool dbl = o_.in_type == 'd' || o_.in_type == 'D';
            const size_t size = dbl ? 8 : 4, n = static_cast<size_t>(o_.binary_columns);
            std::vector<unsigned char> bytes(n * size);
            if (std::fread(bytes.data(), size, n, in) != n) return false;
            std::vector<double> v(n);
            for (size_t k = 0; k < n; ++k) {
                unsigned char *b = &bytes[k * size];
                if (o_.in_type == 'D' || o_.in_type == 'F') std::reverse(b, b + size);
                if (dbl) {
                    std::memcpy(&v[k], b, 8);
                } else {
                    float f;
                    std::memcpy(&f, b, 4);
                    v[k] = f;
                }
            }
            channels_.SetBinary(std::move(v));
            return true;
        }
        // fgets(): a line with its newline, at most kRecordBytes - 1 bytes.
        line->clear();
        for (int c; line->size() < kRecordBytes - 1 && (c = std::getc(in)) != EOF;) {
            line->push_back(static_cast<char>(c));
            if (c == '\n') break;
        }
        if (line->empty()) return false;
        channels_.SetText(*line);
        return true;
    }

    void PutOut() {
        column_ = 0;
        out_.clear();
        if (!template_.empty()) {
            PutTemplate();
        } else {
            for (const auto &[n, e] : outputs_) PutChannel(n, e.Evaluate(cx_, &channels_));
        }
        if (column_ && o_.out_type == 'a') out_ += '\n';
        if (!out_.empty() && std::fwrite(out_.data(), 1, out_.size(), stdout) != out_.size())
            ErrorExit("write error on standard output");
        if (o_.unbuffered) std::fflush(stdout);
    }

    // chanset(), bchanset(): column n after the separators (or zeros) that bring it there.
    void PutChannel(int n, double v) {
        if (o_.out_type == 'a') {
            if (column_ == 0) column_ = 1;
            for (; column_ < n; ++column_) out_ += o_.separator;
            char buf[40];
            std::snprintf(buf, sizeof buf, "%.9g", v);
            out_ += buf;
            return;
        }
        const bool dbl = o_.out_type == 'd' || o_.out_type == 'D';
        const size_t size = dbl ? 8 : 4;
        while (++column_ < n) out_.append(size, '\0');
        unsigned char b[8];
        const float f = static_cast<float>(v);
        std::memcpy(b, dbl ? static_cast<const void *>(&v) : &f, size);
        if (o_.out_type == 'D' || o_.out_type == 'F') std::reverse(b, b + size);
        out_.append(reinterpret_cast<const char *>(b), size);
    }

    // putrec()
    void PutTemplate() {
        bool adjacent_last = false;
        for (size_t i = 0; i < template_.size(); ++i) {
            const Field &f = template_[i];
            const bool adjacent_next =
                o_.blanks_equal && i + 1 < template_.size() &&
                !(template_[i + 1].kind == Field::kLiteral && template_[i + 1].text[0] == ' ');
            char fmt[32], type[16];
            switch (f.kind) {
                case Field::kLiteral:
                    out_ += f.text;
                    adjacent_last = f.text.back() != ' ';
                    break;
                case Field::kString: {
                    const auto it = strings_.find(f.text);
                    if (it == strings_.end() || !it->second.value)
                        ErrorExit(f.text + ": undefined string");
                    const std::string &v = *it->second.value;
                    int n = f.width - static_cast<int>(v.size());
                    if (adjacent_last) out_ += v;
                    if (!(adjacent_last && adjacent_next))
                        while (n-- > 0) out_ += ' ';
                    if (!adjacent_last) out_ += v;
                    adjacent_last = true;
                    break;
                }
                case Field::kNumber: {
                    const int n = f.width;
                    const double dv = f.expression.Evaluate(cx_, &channels_), av = std::fabs(dv);
                    if (n <= 9)
                        std::snprintf(type, sizeof type, "g");
                    else
                        std::snprintf(type, sizeof type, ".%de", n - 5);
                    if (av < 2147483648.0) {
                        const long iv = static_cast<int>(av + .5);
                        if (iv && std::fabs(av - iv) <= av * 1e-14)
                            std::snprintf(type, sizeof type, ".0f");
                    }
                    if (adjacent_last && adjacent_next)
                        std::snprintf(fmt, sizeof fmt, "%%%s", type);
                    else if (adjacent_last)
                        std::snprintf(fmt, sizeof fmt, "%%-%d%s", n, type);
                    else
                        std::snprintf(fmt, sizeof fmt, "%%%d%s", n, type);
                    // (a field may be wider than any buffer: ${x} padded to 80 characters)
                    const int size = std::snprintf(nullptr, 0, fmt, dv);
                    std::string number(static_cast<size_t>(std::max(size, 0)) + 1, '\0');
                    std::snprintf(number.data(), number.size(), fmt, dv);
                    number.pop_back();
                    out_ += number;
                    adjacent_last = true;
                    break;
                }
            }
        }
    }

    const Options &o_;
    cal::Context &cx_;
    RecordChannels channels_;
    std::vector<std::pair<int, cal::Expression>> outputs_;
    std::vector<Field> template_;
    StringVariables strings_;
    std::optional<TemplateInput> input_;
    bool conditional_ = false, set_recno_ = false, set_outno_ = false;
    cal::Expression cond_;
    int column_ = 0;
    std::string out_;
};

// -id N, -if N, -iD, -iF (N columns, 1 without a number).
int BinaryColumns(const char *a, size_t size) {
    const int n = std::isdigit(static_cast<unsigned char>(a[3])) ? std::atoi(a + 3) : 1;
    if (static_cast<size_t>(n) * size > kRecordBytes) ErrorExit("too many input columns");
    return n;
}

int Main(int argc, char **argv) {
    Options o;
    cal::Context cx;
    cx.AllowOutputChannels(true);
    cx.AllowInFunction();
    cx.Set("PI", 3.14159265358979323846, true);
    int i = 1;
    const auto value = [&]() -> std::string {
        if (i + 1 >= argc) Usage(argv[0]);
        return argv[++i];
    };
    for (; i < argc && argv[i][0] == '-'; ++i) {
        const char *a = argv[i];
        switch (a[1]) {
            case 'b':
                o.blanks_equal = !o.blanks_equal;
                break;
            case 'l':
                o.ignore_eol = !o.ignore_eol;
                break;
            case 'p':
                o.passive = !o.passive;
                break;
            case 't':
                o.separator = a[2];
                break;
            case 's': {
                const std::string eq = value();
                const size_t at = eq.find('=');
                if (at != std::string::npos) o.strings[eq.substr(0, at)] = eq.substr(at + 1);
                break;
            }
            case 'f': {
                const std::string file = value(), path = FindOnRaypath(file);
                if (!std::ifstream(path)) ErrorExit("cannot find file '" + file + "'");
                cx.LoadFile(path);
                break;
            }
            case 'e':
                cx.Load(value(), FileLoc{"-e", 0});
                break;
            case 'n':
                o.no_input = true;
                break;
            case 'i':
                switch (a[2]) {
                    case '\0':
                        o.in_type = 'a', o.binary_columns = 0;
                        o.in_format = value();
                        break;
                    case 'n':
                        o.in_count = std::atol(value().c_str());
                        break;
                    case 'a':
                        o.in_type = 'a', o.binary_columns = 0;
                        break;
                    case 'd':
                    case 'D':
                        o.in_type = a[2], o.binary_columns = BinaryColumns(a, 8);
                        break;
                    case 'f':
                    case 'F':
                        o.in_type = a[2], o.binary_columns = BinaryColumns(a, 4);
                        break;
                    default:
                        Usage(argv[0]);
                }
                break;
            case 'o':
                switch (a[2]) {
                    case '\0':
                        o.out_type = 'a', o.out_format = value();
                        break;
                    case 'n':
                        o.out_count = std::atol(value().c_str());
                        break;
                    case 'a':
                    case 'd':
                    case 'D':
                    case 'f':
                    case 'F':
                        o.out_type = a[2];
                        break;
                    default:
                        Usage(argv[0]);
                }
                break;
            case 'w':
                break;  // warnings: ours are errors
            case 'u':
                o.unbuffered = !o.unbuffered;
                break;
            default:
                Usage(argv[0]);
        }
    }
    Calculator calc(o, cx);
    if (o.no_input) {
        if (i < argc) ErrorExit("file argument(s) incompatible with -n");
        calc.NoInput();
        return 0;
    }
    if (i == argc) {
        calc.Process(stdin);
    } else {
        for (; i < argc; ++i) {
            std::FILE *f = std::fopen(argv[i], "rb");
            if (!f) ErrorExit(std::string(argv[i]) + ": cannot open");
            calc.Process(f);
            std::fclose(f);
        }
    }
    if (std::fflush(stdout) != 0) ErrorExit("write error on standard output");
    return 0;
}

}  // namespace
}  // namespace dayflux

int main(int argc, char **argv) { return dayflux::RunTool(argc, argv, dayflux::Main); }
