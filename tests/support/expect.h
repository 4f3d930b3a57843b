#pragma once
// EXPECT_CONTAINS(haystack, needle): a gtest expectation that a message contains a substring,
// printing both when it does not.

#include <string>

#include <gtest/gtest.h>

#define EXPECT_CONTAINS(haystack, needle)                                                     \
  do {                                                                                        \
    const std::string h_ = (haystack);                                                        \
    const std::string n_ = (needle);                                                          \
    EXPECT_TRUE(h_.find(n_) != std::string::npos) << "expected \"" << n_ << "\" in:\n" << h_; \
  } while (false)
