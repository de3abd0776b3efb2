// dctimestep and rmtxop against RADIANCE 5.4's own outputs (test/data/matrix/expected, made by
// the commands in test/data/matrix/run_matrix.sh), RADIANCE's regression references, and bad input.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "test_util.h"

namespace dayflux::test {
namespace fs = std::filesystem;

namespace {

// The working tree the reference commands expect: references/matrix with the inputs, and the
// XML files at the relative paths written in the commands (and so in the output headers).
class ReferenceTree {
  public:
    ReferenceTree() {
        work_ = tmp_.path() / "references" / "matrix";
        fs::create_directories(work_);
        for (const auto &e : fs::directory_iterator(DataDir() / "matrix"))
            if (e.is_regular_file()) fs::create_symlink(e.path(), work_ / e.path().filename());
        const fs::path tmtx = tmp_.path() / "models/subramaniam_tutorial/room/matrices/tmtx";
        fs::create_directories(tmtx);
        fs::create_symlink(DataDir() / "bsdf/clear.xml", tmtx / "clear.xml");
        fs::create_symlink(DataDir() / "bsdf/blinds.xml", tmtx / "blinds.xml");
        fs::create_directories(tmp_.path() / "bsdf");
        fs::create_symlink(DataDir() / "bsdf/frads_klems_aniso_high.xml",
                           tmp_.path() / "bsdf/frads_klems_aniso_high.xml");
        for (const char *sub : {"rcontrib/cds_test.fmx.xz", "gendaymtx/oak_5ph_d_m6.fmx.xz"}) {
            fs::path p = tmp_.path() / "references" / sub;
            fs::create_directories(p.parent_path());
            fs::create_symlink(DataDir() / "matrix" / fs::path(sub).filename(), p);
        }
    }
    const fs::path &work() const { return work_; }

  private:
    TempDir tmp_;
    fs::path work_;
};

std::vector<std::string> ReferenceCommands() {
    std::ifstream f(DataDir() / "matrix/run_matrix.sh");
    std::vector<std::string> cmds;
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '#' || line.rfind("set ", 0) == 0 ||
            line.rfind("xz ", 0) == 0)
            continue;
        // The script writes outputs that are compressed afterwards; keep them plain here.
        cmds.push_back(line);
    }
    return cmds;
}

}  // namespace

class MatrixReferences : public testing::Test {
  protected:
    static void SetUpTestSuite() {
        tree_ = new ReferenceTree();
        for (const std::string &cmd : ReferenceCommands()) {
            CommandResult r = RunCommand(cmd, tree_->work());
            failures_ += r.status ? cmd + "\n" + r.err : "";
        }
    }
    static void TearDownTestSuite() {
        delete tree_;
        tree_ = nullptr;
    }
    static ReferenceTree *tree_;
    static std::string failures_;
};
ReferenceTree *MatrixReferences::tree_ = nullptr;
std::string MatrixReferences::failures_;

TEST_F(MatrixReferences, EveryCommandSucceeds) { EXPECT_EQ(failures_, ""); }

TEST_F(MatrixReferences, OutputsEqualRadianceByteForByte) {
    int compared = 0;
    for (const auto &e : fs::directory_iterator(DataDir() / "matrix/expected")) {
        std::string name = e.path().filename().string();
        std::string expected;
        if (e.path().extension() == ".xz") {
            expected = RunCommand("xzcat '" + e.path().string() + "'", tree_->work()).out;
            name = e.path().stem().string();
        } else {
            expected = ReadFile(e.path());
        }
        const fs::path ours = tree_->work() / name;
        ASSERT_TRUE(fs::exists(ours)) << name;
        EXPECT_EQ(Comparable(ReadFile(ours)), Comparable(expected)) << name;
        ++compared;
    }
    EXPECT_GE(compared, 60);
}

// RADIANCE's own regression test for rmtxop (test/util in RADIANCE's sources).
TEST(RadianceRegression, RmtxopMatchesExactly) {
    TempDir tmp;
    fs::create_symlink(DataDir() / "radiance_util/test.mtx", tmp.path() / "test.mtx");
    CommandResult r =
        RunCommand("rmtxop -ff -c .3 .9 .2 test.mtx -c .7 .2 .3 -t test.mtx", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, ReadFile(DataDir() / "radiance_util/rmtxop.mtx"));
}

// RADIANCE's dctimestep regression test; its sky vector came from genskyvec, made again here.
TEST(RadianceRegression, DctimestepMatchesToPrintedPrecision) {
    TempDir tmp;
    fs::create_symlink(DataDir() / "radiance_util/test.mtx", tmp.path() / "test.mtx");
    fs::create_symlink(DataDir() / "radiance_util/genskyvec_3-21_10-15.vec",
                       tmp.path() / "sky.vec");
    CommandResult r = RunCommand("dctimestep '!rmtxop -ff -t test.mtx' sky.vec", tmp.path());
    ASSERT_EQ(r.status, 0) << r.err;
    std::string ref = ReadFile(DataDir() / "radiance_util/dctimestep.mtx");
    std::istringstream a(r.out.substr(r.out.find("\n\n") + 2)), b(ref.substr(ref.find("\n\n") + 2));
    double x, y;
    int n = 0;
    while (b >> y) {
        ASSERT_TRUE(a >> x);
        // The genskyvec made here agrees with the one behind the reference to 1e-6.
        EXPECT_NEAR(x, y, 2e-6 * std::abs(y) + 1e-6) << "value " << n;
        ++n;
    }
    EXPECT_EQ(n, 145 * 3);
}

// ---- bad input: a message naming the input and the problem, a non-zero exit, no output file.

class BadInput : public testing::Test {
  protected:
    void SetUp() override {
        for (const char *f :
             {"dc.mtx", "dc.fmx", "sky.mtx", "sky.fmx", "vmx.mtx", "A.mtx", "B.mtx", "A.fmx"})
            fs::create_symlink(DataDir() / "matrix" / f, tmp_.path() / f);
        fs::create_symlink(DataDir() / "bsdf/blindsT3.xml", tmp_.path() / "blindsT3.xml");
    }
    void ExpectError(const std::string &cmd, std::initializer_list<const char *> words) {
        CommandResult r = RunCommand(cmd, tmp_.path());
        EXPECT_NE(r.status, 0) << cmd;
        for (const char *w : words)
            EXPECT_NE(r.err.find(w), std::string::npos) << cmd << " said: " << r.err;
    }
    TempDir tmp_;
};

TEST_F(BadInput, MissingFile) {
    ExpectError("dctimestep nosuch.mtx sky.mtx", {"nosuch.mtx", "cannot open"});
}

TEST_F(BadInput, TruncatedBinary) {
    RunCommand("head -c 5000 dc.fmx > short.fmx", tmp_.path());
    ExpectError("dctimestep -of short.fmx sky.fmx",
                {"short.fmx", "unexpected end of input in row", "of 8"});
}

TEST_F(BadInput, TruncatedPipe) {
    ExpectError("dctimestep dc.mtx '!head -c 3000 sky.fmx'",
                {"!head -c 3000 sky.fmx", "unexpected end of input"});
}

TEST_F(BadInput, NonNumericAscii) {
    RunCommand("sed '12s/^ *[^ ]*/1.0x/' A.mtx > bad.mtx", tmp_.path());
    ExpectError("rmtxop bad.mtx", {"bad.mtx:12", "non-numeric value '1.0x'"});
}

TEST_F(BadInput, MissingHeader) {
    RunCommand("printf '1 2 3\\n4 5 6\\n' > plain.txt", tmp_.path());
    ExpectError("rmtxop plain.txt", {"plain.txt:1", "missing header"});
}

TEST_F(BadInput, HeaderWithoutEnd) {
    RunCommand("printf '#?RADIANCE\\nNROWS=2\\n' > open.mtx", tmp_.path());
    ExpectError("rmtxop open.mtx", {"open.mtx", "end of input in header"});
}

TEST_F(BadInput, MissingFormatForDctimestep) {
    RunCommand("grep -v FORMAT= sky.mtx > nofmt.mtx", tmp_.path());
    ExpectError("dctimestep dc.mtx nofmt.mtx", {"nofmt.mtx", "missing FORMAT="});
}

TEST_F(BadInput, WrongDimensions) {
    // vmx has 145 columns, the sky 146 rows.
    ExpectError("dctimestep vmx.mtx sky.mtx", {"vmx.mtx", "145 columns, expected 146"});
    ExpectError("rmtxop A.mtx B.mtx", {"B.mtx", "mismatched dimensions"});
    ExpectError("rmtxop A.mtx + dc.mtx", {"dc.mtx", "sum failed"});
}

TEST_F(BadInput, TensorTreeBsdf) {
    ExpectError("rmtxop blindsT3.xml", {"blindsT3.xml", "tensor-tree"});
}

TEST_F(BadInput, UnknownOption) {
    ExpectError("rmtxop -q A.mtx", {"unknown operation '-q'", "Usage:"});
    ExpectError("dctimestep -x dc.mtx sky.mtx", {"Usage:"});
}

TEST_F(BadInput, NoHalfWrittenOutputFile) {
    RunCommand("head -c 9000 dc.fmx > short.fmx", tmp_.path());
    CommandResult r = RunCommand("dctimestep -of -o result.fmx short.fmx sky.fmx", tmp_.path());
    EXPECT_NE(r.status, 0);
    EXPECT_FALSE(fs::exists(tmp_.path() / "result.fmx"));
    for (const auto &e : fs::directory_iterator(tmp_.path()))
        EXPECT_EQ(e.path().filename().string().find("result"), std::string::npos) << e.path();
}

// ---- inputs through commands and byte orders

TEST(MatrixInputs, CommandInputEqualsFile) {
    TempDir tmp;
    fs::create_symlink(DataDir() / "matrix/A.mtx", tmp.path() / "A.mtx");
    CommandResult a = RunCommand("rmtxop -fa A.mtx", tmp.path());
    CommandResult b = RunCommand("rmtxop -fa '!cat A.mtx'", tmp.path());
    CommandResult c = RunCommand("cat A.mtx | rmtxop -fa -", tmp.path());
    ASSERT_EQ(a.status + b.status + c.status, 0);
    auto data = [](const std::string &s) { return s.substr(s.find("\n\n")); };
    EXPECT_EQ(data(a.out), data(b.out));
    EXPECT_EQ(data(a.out), data(c.out));
}

TEST(MatrixInputs, ByteSwappedFloatReadsTheSame) {
    TempDir tmp;
    std::string f = ReadFile(DataDir() / "matrix/A.fmx");
    size_t end = f.find("\n\n") + 2;
    std::string head = f.substr(0, end), body = f.substr(end);
    ASSERT_NE(head.find("BigEndian=0"), std::string::npos);
    head.replace(head.find("BigEndian=0"), 11, "BigEndian=1");
    for (size_t i = 0; i + 4 <= body.size(); i += 4)
        std::swap(body[i], body[i + 3]), std::swap(body[i + 1], body[i + 2]);
    WriteFile(tmp.path() / "A_be.fmx", head + body);
    fs::create_symlink(DataDir() / "matrix/A.fmx", tmp.path() / "A.fmx");
    CommandResult a = RunCommand("rmtxop -fa A.fmx", tmp.path());
    CommandResult b = RunCommand("rmtxop -fa A_be.fmx", tmp.path());
    ASSERT_EQ(a.status + b.status, 0) << b.err;
    EXPECT_EQ(a.out.substr(a.out.find("\n\n")), b.out.substr(b.out.find("\n\n")));
}

// rmtxop streams a single matrix whose header gives its rows (each block read, transformed and
// written before the next) and holds one that does not: both give the same bytes, header and
// all, and the same messages (-v: once), for each unary operation it streams (-s, -c, those after
// the matrix, output formats) and for a one-component picture, which it does not stream,
// through more blocks than one. A matrix without NROWS, the same bytes otherwise.
TEST(MatrixInputs, RmtxopStreamsWhatItWouldHoldTheSame) {
    TempDir tmp;
    const int rows = 700, cols = 400;  // 2.2 MB of doubles: three blocks of 1 MiB
    std::string text =
        "#?RADIANCE\nsome info line\nNCOLS=" + std::to_string(cols) + "\nNCOMP=3\nFORMAT=ascii\n\n";
    for (int r = 0; r < rows; ++r) {
        for (int j = 0; j < cols; ++j)
            text += std::to_string((r * 7 + j * 3) % 101 * 0.25) + " " + std::to_string(r * 0.5) +
                    " " + std::to_string(j) + "\t";
        text += "\n";
    }
    fs::create_directories(tmp.path() / "held");
    fs::create_directories(tmp.path() / "streamed");
    WriteFile(tmp.path() / "held/m.txt", text);
    WriteFile(tmp.path() / "streamed/m.txt",
              text.replace(text.find("NCOLS"), 0, "NROWS=" + std::to_string(rows) + "\n"));
    for (const char *args : {"-ff -c 47.4 119.9 11.6 -", "-v -fa -s 2 .5 3 -", "-fd - -v -s 4",
                             "-fc -c .2 .3 .5 .1 .1 .8 .6 .3 .1 -", "-c .3 .3 .4 - -s 2",
                             "-fa -c 1 0 0 0 1 0 -", "-v -fc -c .3 .3 .4 -"}) {
        SCOPED_TRACE(args);
        const std::string cmd = std::string("cat m.txt | rmtxop ") + args;
        const CommandResult held = RunCommand(cmd, tmp.path() / "held"),
                            streamed = RunCommand(cmd, tmp.path() / "streamed");
        ASSERT_EQ(held.status, 0) << held.err;
        ASSERT_EQ(streamed.status, 0) << streamed.err;
        EXPECT_GT(streamed.out.size(), size_t{rows} * cols);
        EXPECT_EQ(streamed.out, held.out);
        EXPECT_EQ(streamed.err, held.err);
    }
    // A stream that ends before its header's rows: an error, after what was written.
    WriteFile(tmp.path() / "streamed/short.txt", text.substr(0, text.size() / 2));
    const CommandResult cut = RunCommand("cat short.txt | rmtxop -ff -", tmp.path() / "streamed");
    EXPECT_NE(cut.status, 0);
    EXPECT_NE(cut.err.find("<stdin>"), std::string::npos) << cut.err;
}

// A BSDF file with "--" inside a comment is taken, with a warning naming its line: XML forbids
// it, and RADIANCE's reader refuses the file ("unclosed <!--"). A clean comment draws none.
TEST(MatrixInputs, DashesInAnXmlCommentAreWarnedAbout) {
    TempDir tmp;
    const std::string xml = ReadFile(DataDir() / "bsdf/clear.xml");
    const size_t body = xml.find('>') + 1;  // after the XML declaration
    WriteFile(tmp.path() / "bad.xml",
              xml.substr(0, body) + "\n<!-- made by a tool --option 1 -->" + xml.substr(body));
    WriteFile(tmp.path() / "good.xml",
              xml.substr(0, body) + "\n<!-- made by a tool, option 1 -->" + xml.substr(body));
    const CommandResult bad = RunCommand("rmtxop -ff bad.xml", tmp.path()),
                        good = RunCommand("rmtxop -ff good.xml", tmp.path());
    ASSERT_EQ(bad.status, 0) << bad.err;
    ASSERT_EQ(good.status, 0) << good.err;
    EXPECT_NE(bad.err.find("bad.xml:2: '--' inside a comment"), std::string::npos) << bad.err;
    EXPECT_EQ(good.err, "");
    EXPECT_EQ(bad.out.substr(bad.out.find("\n\n")), good.out.substr(good.out.find("\n\n")));
}

// Small programs against RADIANCE 5.4a's own (test/data/PROGRAM: commands.txt, and expected/
// made by test/data/make_expected.sh): each command's standard output byte for byte, and its exit
// status.
class RadiancePrograms : public ::testing::TestWithParam<std::pair<const char *, int>> {};

TEST_P(RadiancePrograms, OutputsEqualRadianceByteForByte) {
    const auto [program, commands_expected] = GetParam();
    const fs::path dir = DataDir() / program;
    std::istringstream commands(ReadFile(dir / "commands.txt"));
    int compared = 0;
    for (std::string line; std::getline(commands, line);) {
        if (line.empty() || line[0] == '#') continue;
        const size_t t1 = line.find('\t'), t2 = line.find('\t', t1 + 1);
        ASSERT_NE(t2, std::string::npos) << line;
        const std::string name = line.substr(0, t1), args = line.substr(t1 + 1, t2 - t1 - 1),
                          input = line.substr(t2 + 1);
        SCOPED_TRACE(name);
        const CommandResult r = RunCommand(std::string(program) + " " + args + " < " +
                                               (input == "-" ? std::string("/dev/null") : input),
                                           dir);
        EXPECT_EQ(r.out + "status " + std::to_string(r.status) + "\n",
                  ReadFile(dir / "expected" / (name + ".out")));
        ++compared;
    }
    EXPECT_EQ(compared, commands_expected);
}

INSTANTIATE_TEST_SUITE_P(Matrix, RadiancePrograms,
                         ::testing::Values(std::pair{"getinfo", 15}, std::pair{"total", 31},
                                           std::pair{"rcollate", 33}, std::pair{"gensky", 32},
                                           std::pair{"oconv", 27}, std::pair{"rcalc", 40},
                                           std::pair{"gendaylit", 34}, std::pair{"xform", 26},
                                           std::pair{"cnt", 7}),
                         [](const auto &info) { return std::string(info.param.first); });

// An rcalc input template that can match without taking any input (numbers only, -l) skips what
// it cannot read instead of matching it forever, as RADIANCE's does.
TEST(Rcalc, TemplateThatTakesNoInputDoesNotHang) {
    TempDir tmp;
    const CommandResult r =
        RunCommand("printf 'x 1 y 22' | timeout 10 rcalc -l -i '${a}' -e '$1=a'", tmp.path());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.out, "1\n22\n");
}

// Where RADIANCE's oconv dies after writing its header (a bad scene, a cube too small), ours
// writes nothing, so no partial octree is left to be taken for one; the message names the file
// and line where there is one.
TEST(Oconv, BadInputLeavesNoOctree) {
    const fs::path dir = DataDir() / "oconv";
    const struct {
        const char *args, *message;
    } cases[] = {
        {"added.rad", "added.rad:1: undefined modifier 'wall' for sphere 'ball2'"},
        {"-b 0 0 0 1 room.rad", "boundary does not encompass scene"},
        {"-i inst.oct xforms.rad", "boundary does not encompass scene"},
        {"-b 0 0 0 100 -i inst.oct added.rad", "only one of '-b' or '-i'"},
        {"missing.rad", "missing.rad"},
        {"-n", "option -n needs a positive whole number"},  // RADIANCE's crashes
        {"-r 0 room.rad", "'0' is not a positive whole number"},
        {"-i room.rad added.rad", "room.rad: not a RADIANCE octree"},
    };
    for (const auto &c : cases) {
        SCOPED_TRACE(c.args);
        const CommandResult r = RunCommand(std::string("oconv ") + c.args, dir);
        EXPECT_EQ(r.status, 1);
        EXPECT_EQ(r.out, "");
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
    }
}

}  // namespace dayflux::test
