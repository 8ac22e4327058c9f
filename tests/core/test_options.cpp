// SPDX-License-Identifier: BSD-3-Clause
// The option tables (docs/design.md, "Options"): rows made by hand parse,
// check and nest as they say; every table of the library is well formed.
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "radargauss/core/options.hpp"
#include "radargauss/slam/radar_slam.hpp"
#include "radargauss/slam/relocalization.hpp"

namespace radargauss {
namespace {

struct Inner {
  double gain = 1.0;
  std::size_t capacity = 16;
  std::size_t floor = 8;
};

struct Outer {
  bool flag = false;
  Eigen::Vector3d angles = Eigen::Vector3d::Zero();
  SE3d pose;
  Inner inner;
};

OptionTable<Inner> InnerTable() {
  using O = Inner;
  return {RADARGAUSS_OPTION(O, "gain", gain).In(0.0, 10.0).Above(0.0).Unit("m").Help("a gain"),
          RADARGAUSS_OPTION(O, "capacity", capacity).In(1, 100).NotBelow("floor"),
          RADARGAUSS_OPTION(O, "floor", floor).In(1, 100)};
}

OptionTable<Outer> OuterTable() {
  using O = Outer;
  OptionTable<O> table = {RADARGAUSS_OPTION(O, "flag", flag).Sensor(),
                          RADARGAUSS_OPTION(O, "angles", angles).In(-45.0, 45.0), RADARGAUSS_OPTION(O, "pose", pose)};
  AppendNested(
      table, InnerTable(), +[](O & o) -> auto& { return o.inner; }, "inner", "inner_");
  return table;
}

TEST(Options, RowsTellTheirFlagRangeAndTypeFromTheMember) {
  const OptionTable<Outer> table = OuterTable();
  ASSERT_EQ(table.size(), 6u);
  const Option<Outer>& gain = *FindOption(table, "inner_gain");
  EXPECT_EQ(gain.Flag(), "--inner-gain");
  EXPECT_EQ(gain.path, "inner.gain");
  EXPECT_EQ(gain.RangeText(), "(0, 10]");
  EXPECT_EQ(gain.TypeText(), "FLOAT");
  EXPECT_EQ(FindOption(table, "inner_capacity")->kind, OptionKind::kInteger);
  EXPECT_EQ(FindOption(table, "inner_capacity")->at_least, "inner_floor");
  EXPECT_EQ(FindOption(table, "flag")->kind, OptionKind::kFlag);
  EXPECT_EQ(FindOption(table, "flag")->group, OptionGroup::kSensor);
  EXPECT_EQ(FindOption(table, "angles")->min_count, 3u);
  EXPECT_EQ(FindOption(table, "pose")->max_count, 7u);
  EXPECT_EQ(FindOption(table, "missing"), nullptr);
}

TEST(Options, WordsParseOrAreRefusedInTheirOwnSpelling) {
  const OptionTable<Outer> table = OuterTable();
  const Option<Outer>& gain = *FindOption(table, "inner_gain");
  EXPECT_EQ(std::get<double>(gain.Parse({"2.5"})), 2.5);
  for (const auto& [word, message] : {std::pair<std::string, std::string>{"0", "0 is not in (0, 10]"},
                                      {"1e300", "1e300 is not in (0, 10]"},
                                      {"nan", "nan is not a finite number"},
                                      {"2x", "2x is not a number"}}) {
    try {
      gain.Parse({word});
      ADD_FAILURE() << word << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
  const Option<Outer>& angles = *FindOption(table, "angles");
  EXPECT_THROW(angles.Parse({"1", "2"}), std::invalid_argument);
  EXPECT_THROW(angles.Parse({"1", "2", "46"}), std::invalid_argument);
  const Option<Outer>& pose = *FindOption(table, "pose");
  EXPECT_THROW(pose.Parse({"0", "0", "0", "0", "0", "0", "0"}), std::invalid_argument);  // no unit quaternion
  Outer outer;
  pose.set(outer, pose.Parse({"1", "2", "3", "0", "0", "1", "0"}));
  EXPECT_TRUE(outer.pose.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_NEAR(std::abs(outer.pose.rotation().quaternion().z()), 1.0, 1e-15);
  const Option<Outer>& capacity = *FindOption(table, "inner_capacity");
  EXPECT_THROW(capacity.Parse({"2.5"}), std::invalid_argument);
  EXPECT_THROW(capacity.Parse({"101"}), std::invalid_argument);
  EXPECT_EQ(std::get<std::int64_t>(capacity.Parse({"100"})), 100);
}

TEST(Options, CheckNamesTheOptionAndBothOfAPair) {
  const OptionTable<Outer> table = OuterTable();
  Outer outer;
  EXPECT_NO_THROW(CheckOptions(table, outer));
  outer.inner.capacity = 4;
  try {
    CheckOptions(table, outer);
    ADD_FAILURE() << "a capacity below its floor was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "inner_capacity (4) must be at least inner_floor (8)");
  }
  try {
    CheckOptions(table, outer, true);
    ADD_FAILURE();
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--inner-capacity (4) must be at least --inner-floor (8)");
  }
  outer.inner.floor = 4;
  EXPECT_NO_THROW(CheckOptions(table, outer));
  outer.angles.x() = 50.0;
  EXPECT_THROW(CheckOptions(table, outer), std::invalid_argument);
}

TEST(Options, ANameTakenTwiceIsRefusedWhenTheTableIsBuilt) {
  OptionTable<Outer> table = OuterTable();
  EXPECT_THROW(AppendNested(
                   table, InnerTable(), +[](Outer & o) -> auto& { return o.inner; }, "inner", "inner_"),
               std::logic_error);
}

TEST(Options, ValuesPrintAsTheyRead) {
  EXPECT_EQ(FormatOptionValue(OptionValue(100.0)), "100");
  EXPECT_EQ(FormatOptionValue(OptionValue(0.1)), "0.1");
  EXPECT_EQ(FormatOptionValue(OptionValue(1e-10)), "1e-10");
  EXPECT_EQ(FormatOptionValue(OptionValue(std::vector<double>{1, 1, 90})), "[1,1,90]");
  EXPECT_EQ(FormatOptionValue(OptionValue(true)), "true");
}

// Every table of the library: its defaults pass its own checks, each row
// reads back what it set, and its names are unique (else building it throws).
template <typename Options>
void ExpectWellFormed(const OptionTable<Options>& table) {
  const Options defaults{};
  EXPECT_NO_THROW(CheckOptions(table, defaults));
  for (const Option<Options>& option : table) {
    Options options{};
    const OptionValue value = option.get(options);
    EXPECT_EQ(option.Check(value), "") << option.name;
    option.set(options, value);
    EXPECT_EQ(FormatOptionValue(option.get(options)), FormatOptionValue(value)) << option.name;
    EXPECT_FALSE(option.help.empty()) << option.name;
  }
}

TEST(Options, EveryTableOfTheLibraryIsWellFormed) {
  ExpectWellFormed(SlamOptionTable());
  ExpectWellFormed(RelocalizationOptionTable());
  EXPECT_GT(OdometryOptionTable().size(), 80u);
  EXPECT_GT(SlamOptionTable().size(), OdometryOptionTable().size());
}

}  // namespace
}  // namespace radargauss
