// The view page's text encodings: JSON strings that cannot end the page's <script> element,
// HTML escaping, JSON numbers (no NaN), little-endian bytes, and base64 appended to a string.

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <sph/render/view_codec.h>

namespace sph {
namespace {

using namespace detail;

TEST(ViewCodec, JsonStringsCannotEndTheScriptElement) {
  EXPECT_EQ(json_string("dam break"), "\"dam break\"");
  EXPECT_EQ(json_string("a</script><b>"), "\"a\\u003c/script>\\u003cb>\"");
  EXPECT_EQ(json_string("say \"hi\"\n"), "\"say \\\"hi\\\"\\n\"");
  EXPECT_EQ(json_string("\xC3\xA9t\xC3\xA9"), "\"\xC3\xA9t\xC3\xA9\"") << "UTF-8 is kept";
  EXPECT_EQ(json_string("\xFF"), "\"\xEF\xBF\xBD\"") << "invalid UTF-8 becomes U+FFFD";
}

TEST(ViewCodec, HtmlEscapeCoversMarkupAndQuotes) {
  EXPECT_EQ(html_escape("a & b <c> \"d\" 'e'"), "a &amp; b &lt;c&gt; &quot;d&quot; 'e'");
  EXPECT_EQ(html_escape(""), "");
}

TEST(ViewCodec, JsonNumbersAreFiniteAndRoundTrip) {
  EXPECT_EQ(json_number(0.1), "0.1");
  EXPECT_EQ(json_number(-2.5e-7), "-2.5e-07");
  EXPECT_EQ(std::stod(json_number(1.0 / 3.0)), 1.0 / 3.0);
  EXPECT_EQ(json_number(std::numeric_limits<double>::quiet_NaN()), "0");
  EXPECT_EQ(json_number(std::numeric_limits<double>::infinity()), "0");
}

TEST(ViewCodec, LittleEndianAndAppendedBase64) {
  EXPECT_EQ(little_endian({0x0102, 0xffee}), (std::vector<std::uint8_t>{0x02, 0x01, 0xee, 0xff}));
  std::string out = "x:";
  const std::vector<std::uint8_t> bytes{'M', 'a'};
  append_base64(out, bytes);
  EXPECT_EQ(out, "x:TWE=");
  EXPECT_EQ(out.substr(2), base64_encode(bytes));
  for (std::size_t n = 0; n < 8; ++n) EXPECT_EQ(base64_size(n), base64_encode(std::vector<std::uint8_t>(n)).size());
}

}  // namespace
}  // namespace sph
