#include "matrix/header.h"

#include <gtest/gtest.h>

namespace dayflux {
namespace {

MatrixHeader Parse(const std::string &text) {
    auto in = InputSource::FromString(text, "t.mtx");
    return ReadHeader(*in);
}

std::string ErrorOf(const std::string &text) {
    try {
        Parse(text);
    } catch (const UserError &e) {
        return e.what();
    }
    return "";
}

TEST(Header, ReadsVariablesAndKeepsInfoInOrder) {
    MatrixHeader h = Parse(
        "#?RADIANCE\noconv a.rad\nNROWS=12\nNCOLS=5\nNCOMP=3\nBigEndian=1\nFORMAT=float\n"
        "rcontrib -I+\n\nDATA");
    EXPECT_EQ(h.nrows, 12);
    EXPECT_EQ(h.ncols, 5);
    EXPECT_EQ(h.ncomp, 3);
    EXPECT_EQ(h.format, DataFormat::Float);
    ASSERT_TRUE(h.big_endian.has_value());
    EXPECT_TRUE(*h.big_endian);
    EXPECT_EQ(h.info, "oconv a.rad\nrcontrib -I+\n");
}

TEST(Header, AcceptsCarriageReturnsAndExposure) {
    MatrixHeader h = Parse(
        "#?RADIANCE\r\nEXPOSURE=2\r\nEXPOSURE=0.5\r\nCOLORCORR=1 2 "
        "4\r\nFORMAT=32-bit_rle_rgbe\r\n\r\n");
    EXPECT_EQ(h.format, DataFormat::RGBE);
    EXPECT_DOUBLE_EQ(h.exposure[0], 1);
    EXPECT_DOUBLE_EQ(h.exposure[2], 4);
}

TEST(Header, ErrorsNameTheFileLineAndProblem) {
    EXPECT_EQ(ErrorOf("1 2 3\n"),
              "t.mtx:1: missing header: the first line should be '#?RADIANCE', not '1 2 3'");
    EXPECT_EQ(ErrorOf("#?RADIANCE\nNROWS=3\n"),
              "t.mtx:3: unexpected end of input in header (no blank line)");
    EXPECT_EQ(ErrorOf("#?RADIANCE\nNROWS=x3\n\n"), "t.mtx:2: bad NROWS value 'x3' in header");
    EXPECT_EQ(ErrorOf("#?RADIANCE\nFORMAT=int16\n\n"),
              "t.mtx:2: unknown data format 'int16' in header");
    EXPECT_EQ(ErrorOf(""), "t.mtx: empty input where a matrix header was expected");
    EXPECT_EQ(ErrorOf(std::string("\x01\x02", 2)),
              "t.mtx: not a RADIANCE file: binary data where a header was expected");
}

TEST(Header, CommandLineQuotedAsRadianceDoes) {
    const char *argv[] = {"rmtxop", "-c", "47.4 119.9 11.6", "it's", "a\"b"};
    EXPECT_EQ(HeaderStart(5, const_cast<char **>(argv)),
              "#?RADIANCE\nrmtxop -c \"47.4 119.9 11.6\" \"it's\" 'a\"b'\n");
}

TEST(Header, FieldsCarryByteOrderOnlyForBinary) {
    EXPECT_EQ(HeaderFields(2, 3, 1, DataFormat::Ascii),
              "NROWS=2\nNCOLS=3\nNCOMP=1\nFORMAT=ascii\n\n");
    EXPECT_NE(HeaderFields(2, 3, 3, DataFormat::Double).find("BigEndian="), std::string::npos);
}

}  // namespace
}  // namespace dayflux
