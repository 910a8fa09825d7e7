// Numbers as text (core/common/number_text.h): the strings of each format the core prints, at the
// precisions its notes, messages and files use, including NaN, infinities and negative zero.
#include "cvg_bench/core/common/number_text.h"

#include <gtest/gtest.h>

#include <limits>

namespace cvg_bench {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

TEST(NumberText, StreamDigitsAtEachPrecision) {
  EXPECT_EQ(numberText(0.1, 3), "0.1");
  EXPECT_EQ(numberText(1e-7, 3), "1e-07");
  EXPECT_EQ(numberText(12345.678, 3), "1.23e+04");
  EXPECT_EQ(numberText(12345.678, 4), "1.235e+04");
  EXPECT_EQ(numberText(12345.678, 6), "12345.7");
  EXPECT_EQ(numberText(0.1, 15), "0.1");
  EXPECT_EQ(numberText(0.1, 17), "0.10000000000000001");
  EXPECT_EQ(numberText(1e-7, 17), "9.9999999999999995e-08");
  EXPECT_EQ(numberText(12345.678, 17), "12345.678");
  EXPECT_EQ(numberText(0.5, 2), "0.5");
  EXPECT_EQ(numberText(100.0, 3), "100");
  EXPECT_EQ(numberText(1000.0, 3), "1e+03");
}

TEST(NumberText, StreamNonFiniteAndSignedZero) {
  EXPECT_EQ(numberText(kNaN, 3), "nan");
  EXPECT_EQ(numberText(kInf, 6), "inf");
  EXPECT_EQ(numberText(-kInf, 17), "-inf");
  EXPECT_EQ(numberText(-0.0, 3), "-0");
  EXPECT_EQ(numberText(0.0, 3), "0");
}

TEST(NumberText, PrintfGDigitsAtEachPrecision) {
  EXPECT_EQ(printfGText(0.1, 3), "0.1");
  EXPECT_EQ(printfGText(1e-7, 6), "1e-07");
  EXPECT_EQ(printfGText(12345.678, 3), "1.23e+04");
  EXPECT_EQ(printfGText(12345.678, 6), "12345.7");
  EXPECT_EQ(printfGText(12345.678, 8), "12345.678");
  EXPECT_EQ(printfGText(0.1, 17), "0.10000000000000001");
  EXPECT_EQ(printfGText(-1e-7, 17), "-9.9999999999999995e-08");
  EXPECT_EQ(printfGText(kNaN, 6), "nan");
  EXPECT_EQ(printfGText(kInf, 17), "inf");
  EXPECT_EQ(printfGText(-kInf, 3), "-inf");
  EXPECT_EQ(printfGText(-0.0, 17), "-0");
}

TEST(NumberText, PrintfGLongerThanItsBuffer) {
  const std::string s = printfGText(1e300, 400);  // every digit of the double: 301 of them
  EXPECT_EQ(s.size(), 301u);
  EXPECT_EQ(s.substr(0, 20), "10000000000000000525");
}

TEST(NumberText, StreamAndPrintfAgree) {  // in the C locale, the one the core runs in
  for (double v : {0.1, 1e-7, 12345.678, -2.5e-300, 6.02e23, 1.0 / 3.0, -0.0, kNaN, kInf})
    for (int p : {3, 4, 6, 8, 15, 17})
      EXPECT_EQ(numberText(v, p), printfGText(v, p)) << v << " " << p;
}

TEST(NumberText, FixedDecimals) {
  EXPECT_EQ(fixedText(0.1, 6), "0.100000");
  EXPECT_EQ(fixedText(1e-7, 6), "0.000000");
  EXPECT_EQ(fixedText(12345.678, 6), "12345.678000");
  EXPECT_EQ(fixedText(12345.678, 2), "12345.68");
  EXPECT_EQ(fixedText(1e-3, 6), std::to_string(1e-3));
  EXPECT_EQ(fixedText(kNaN, 6), "nan");
  EXPECT_EQ(fixedText(-kInf, 6), "-inf");
  EXPECT_EQ(fixedText(-0.0, 6), "-0.000000");
}

TEST(NumberText, ValueWithInterval) {
  EXPECT_EQ(valueWithInterval(0.1, 1e-7, 12345.678, 3), "0.1 [1e-07, 1.23e+04]");
  EXPECT_EQ(valueWithInterval(0.1, 1e-7, 12345.678, 4), "0.1 [1e-07, 1.235e+04]");
  EXPECT_EQ(valueWithInterval(-0.0, kNaN, kInf, 3), "-0 [nan, inf]");
  EXPECT_EQ(valueWithInterval(12345.678, 12000.0, 13000.0, 3, "deg/h"),
            "1.23e+04 deg/h [1.2e+04, 1.3e+04]");
}

}  // namespace
}  // namespace cvg_bench
