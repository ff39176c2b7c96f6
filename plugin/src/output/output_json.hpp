// SPDX-License-Identifier: MIT
// The output layer's JSON documents as nlohmann-json values (internal: the public header
// output.hpp gives them as text, so that nothing of nlohmann-json leaks to its users).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "rheofeed/measure/metrics.hpp"

namespace rheofeed::scene {

/// Keys in the order written, so that a file reads in the order of its documentation.
using OrderedJson = nlohmann::ordered_json;

/// The feeder metrics object of feederJson (output.hpp), before it is written.
OrderedJson feederJsonValue(const FeederMetrics& feeder);

/// `value` as one line of JSON text. Non-finite numbers are written as null (nlohmann-json's
/// rule); bytes that are not UTF-8 (a file name in another encoding) become U+FFFD instead of
/// throwing, so that a run's file is always written.
std::string oneLineJson(const OrderedJson& value);

}  // namespace rheofeed::scene
