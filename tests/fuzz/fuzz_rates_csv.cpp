// SPDX-License-Identifier: Apache-2.0
// The rates CSV that predict writes and eval reads.
#include "fuzz_support.hpp"
#include "inertialnet/io/rates_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = inertialnet::fuzz::as_file(data, size, "rates.csv");
  inertialnet::fuzz::expect_only_inertialnet_errors([&] {
    const inertialnet::RatesTable table = inertialnet::read_rates_csv(path);
    for (const auto& name : table.extra_names) table.column(name);
    // What eval does with a table it read: the statuses, the answered rows, a validation.
    table.validate();
    for (const auto& name : table.status_names) table.ok_rows(name.substr(6));
  });
  return 0;
}
