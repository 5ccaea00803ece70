// The one number formatter of error and warning messages: exact when the
// shortest round-trip text is short, 6 significant digits otherwise, small
// and large magnitudes in scientific notation.
#include <catch2/catch.hpp>

#include <limits>

#include <posefuse/io/detail/message_number.hpp>

using posefuse::detail::message_number;

TEST_CASE("message_number: short, human numbers for messages", "[io][messages]") {
  CHECK(message_number(104.99993599999999) == "105");
  CHECK(message_number(2.000000849517135) == "2");
  CHECK(message_number(-1.0001710497327156) == "-1.00017");
  CHECK(message_number(1e-9) == "1e-09");
  CHECK(message_number(0.05) == "0.05");
  CHECK(message_number(1e308) == "1e+308");
  CHECK(message_number(-3) == "-3");
  CHECK(message_number(0) == "0");
  CHECK(message_number(123456) == "123456");
  CHECK(message_number(1234567) == "1.23457e+06");
  CHECK(message_number(1000000) == "1e+06");
  CHECK(message_number(751.5) == "751.5");
  CHECK(message_number(0.000123456) == "0.000123456");
  CHECK(message_number(std::numeric_limits<double>::infinity()) == "inf");
  CHECK(message_number(-std::numeric_limits<double>::infinity()) == "-inf");
  CHECK(message_number(std::numeric_limits<double>::quiet_NaN()) == "nan");
}
