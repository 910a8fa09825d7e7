// Numbers as text for the core's notes, messages and files: one definition of each format the
// stages print numbers in (was a file-local helper in each source).
#pragma once

#include <string>

namespace cvg_bench {

/// `v` as an output stream writes it with `precision` significant digits (std::ostringstream,
/// default float field, the stream's locale): numberText(0.1, 3) "0.1", numberText(1e-7, 3)
/// "1e-07", numberText(12345.678, 3) "1.23e+04", "nan", "inf", "-0".
std::string numberText(double v, int precision);

/// `v` as printf's "%.<precision>g" writes it (std::snprintf, the C locale's decimal point):
/// printfGText(12345.678, 6) "12345.7", printfGText(0.1, 17) "0.10000000000000001". Same digits as
/// numberText; kept apart so that each former helper keeps its own formatting path.
std::string printfGText(double v, int precision);

/// `v` in std::fixed notation with `precision` decimals (std::ostringstream): fixedText(0.1, 6)
/// "0.100000", std::to_string's format at precision 6.
std::string fixedText(double v, int precision);

/// "value [low, high]", each numberText(.., precision); with a `unit`, "value unit [low, high]".
std::string valueWithInterval(double value, double low, double high, int precision,
                              const std::string& unit = "");

}  // namespace cvg_bench
