// ThicknessField: lattice, bilinear sampling, heightmap export, sparsity.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "deposition/process.hpp"
#include "deposition/thickness_field.hpp"
#include "deposition_test_util.hpp"

namespace depotwin {
namespace {

TEST(ThicknessField, TileIndexingIsFloorDivision) {
  using Tiles = ThicknessField::Tiles;
  EXPECT_EQ(Tiles::tile_of(0), 0);
  EXPECT_EQ(Tiles::tile_of(63), 0);
  EXPECT_EQ(Tiles::tile_of(64), 1);
  EXPECT_EQ(Tiles::tile_of(-1), -1);
  EXPECT_EQ(Tiles::tile_of(-64), -1);
  EXPECT_EQ(Tiles::tile_of(-65), -2);
  EXPECT_EQ(Tiles::local_of(-1), 63);
  EXPECT_EQ(Tiles::local_of(-64), 0);
}

TEST(ThicknessField, CellsBilinearAndVolume) {
  ThicknessField field(0.5);
  field.add_to_cell(-1, -1, 1.0);
  field.add_to_cell(0, -1, 3.0);
  field.add_to_cell(-65, 70, 2.0);
  EXPECT_EQ(field.allocated_tiles(), 3u);  // tiles (-1,-1), (0,-1), (-2,1)
  EXPECT_DOUBLE_EQ(field.cell_thickness_mm(-1, -1), 1.0);
  EXPECT_DOUBLE_EQ(field.cell_thickness_mm(5, 5), 0.0);
  // halfway between the centres of (-1, -1) and (0, -1), and a quarter up towards row 0
  EXPECT_DOUBLE_EQ(field.thickness_mm_at(-0.25, -0.5), 2.0);
  EXPECT_DOUBLE_EQ(field.thickness_mm_at(-0.25, -0.375), 0.75 * 2.0);
  EXPECT_DOUBLE_EQ(field.total_volume_mm3(), (1.0 + 3.0 + 2.0) * 0.25);
  const FieldBounds b = field.bounds();
  ASSERT_FALSE(b.empty);
  EXPECT_DOUBLE_EQ(b.x_lo_mm, -65 * 0.5);
  EXPECT_DOUBLE_EQ(b.x_hi_mm, 0.0);
  EXPECT_DOUBLE_EQ(b.y_lo_mm, -0.5);
  EXPECT_DOUBLE_EQ(b.y_hi_mm, 35.0);
  EXPECT_THROW(ThicknessField(0.0), InputError);
}

// the dense export holds exactly the field's cell values (um) at its cell centres
TEST(ThicknessField, HeightMapMatchesValueAt) {
  DepositionSettings settings;
  AerosolProcess process(settings, 0.0);
  test::drive(
      process, 0.0, 1.0, 1e-3,
      [](double t) { return Vec3(2.0 * std::cos(3.0 * t), 2.0 * std::sin(3.0 * t), 0.0); },
      [](double) { return 1.0; }, [](double) { return 0.0; }, [](double) { return 0.0; });
  const ThicknessField& field = process.field();
  const HeightMap map = field.to_heightmap(-1.0, -1.0, 3.0, 3.0);
  EXPECT_EQ(map.nx, 161);
  EXPECT_EQ(map.ny, 161);
  EXPECT_DOUBLE_EQ(map.cell_mm, 0.025);
  double worst = 0.0;
  for (int iy = 0; iy < map.ny; ++iy) {
    for (int ix = 0; ix < map.nx; ++ix) {
      const double x = map.origin_x_mm + ix * map.cell_mm;
      const double y = map.origin_y_mm + iy * map.cell_mm;
      const double expected_um = 1000.0 * field.thickness_mm_at(x, y);
      worst = std::max(worst, std::abs(map.at(ix, iy) - expected_um));
    }
  }
  EXPECT_LT(worst, 1e-6 * map.max_value());
  EXPECT_GT(map.max_value(), 1.0f);

  // a strided export averages blocks: volume is preserved over the whole field
  const HeightMap coarse = field.to_heightmap(3);
  double volume_mm3 = 0.0;
  for (float v : coarse.thickness_um) volume_mm3 += v * 1e-3 * coarse.cell_mm * coarse.cell_mm;
  EXPECT_NEAR(volume_mm3, field.total_volume_mm3(), 1e-5 * field.total_volume_mm3());
  EXPECT_DOUBLE_EQ(coarse.cell_mm, 0.075);

  // a stride keeping a 161 x 161 export within 2000 cells: 3 -> 54^2 = 2916, 4 -> 41^2 = 1681
  const int stride = field.stride_for_max_cells(-1.0, -1.0, 3.0, 3.0, 2000);
  EXPECT_EQ(stride, 4);
  const HeightMap limited = field.to_heightmap(-1.0, -1.0, 3.0, 3.0, stride);
  EXPECT_LE(static_cast<size_t>(limited.nx) * limited.ny, 2000u);
}

// a 100 mm line across a 100 x 100 mm bed at 10 um cells: only the printed band is stored
TEST(ThicknessField, MemoryGrowsWithPrintedAreaNotBed) {
  DepositionSettings settings;
  settings.sigma_mm = 0.1;
  AerosolProcess process(settings, 0.01);
  test::drive(
      process, 0.0, 100.0 / 3.0, 1e-2, [](double t) { return Vec3(3.0 * t, 50.0, 0.0); },
      [](double) { return 1.0; }, [](double) { return 0.0; }, [](double) { return 0.0; });
  const double bed_cells = (100.0 / 0.01) * (100.0 / 0.01);
  const double allocated = static_cast<double>(process.field().allocated_cells());
  RecordProperty("allocated_fraction_of_bed", std::to_string(allocated / bed_cells));
  EXPECT_LT(allocated, 0.05 * bed_cells);
  EXPECT_NEAR(process.field().total_volume_mm3(), process.account().landed_mm3,
              1e-12 * process.account().landed_mm3);
}

// layers stacked: the sum of two fields, cell by cell, volumes adding up; fields of other cells
// refused
TEST(ThicknessField, AddStacksFieldsCellByCell) {
  ThicknessField a(0.1), b(0.1);
  a.add_to_cell(3, -70, 0.002);
  a.add_to_cell(200, 5, 0.001);
  b.add_to_cell(3, -70, 0.0005);
  b.add_to_cell(-1, -1, 0.004);
  a.add(b);
  EXPECT_DOUBLE_EQ(a.cell_thickness_mm(3, -70), 0.0025);
  EXPECT_DOUBLE_EQ(a.cell_thickness_mm(200, 5), 0.001);
  EXPECT_DOUBLE_EQ(a.cell_thickness_mm(-1, -1), 0.004);
  EXPECT_NEAR(a.total_volume_mm3(), (0.0025 + 0.001 + 0.004) * 0.01, 1e-15);
  ThicknessField c(0.2);
  EXPECT_THROW(a.add(c), InternalError);
}

// the normal-thickness correction: each cell times a factor of its centre's position
TEST(ThicknessField, ScaleCellsUsesEachCellCentre) {
  ThicknessField field(0.5);
  field.add_to_cell(4, -2, 1.0);  // centre (2, -1)
  field.add_to_cell(-3, 6, 2.0);  // centre (-1.5, 3)
  field.scale_cells([](double x, double y) { return 0.5 + 0.1 * x + 0.01 * y; });
  EXPECT_DOUBLE_EQ(field.cell_thickness_mm(4, -2), 1.0 * (0.5 + 0.2 - 0.01));
  EXPECT_DOUBLE_EQ(field.cell_thickness_mm(-3, 6), 2.0 * (0.5 - 0.15 + 0.03));
  EXPECT_EQ(field.cell_thickness_mm(0, 0), 0.0);
}

// zero() clears only the cells written since the last zero() (their bounding box), so every way
// of writing must widen that box: the kernel's footprints, add_to_cell, add() and raw tile
// writes. After each, every cell reads 0 again and the tiles stay allocated.
TEST(ThicknessField, ZeroClearsEveryWrittenCellWhateverWroteIt) {
  DepositionSettings settings;
  settings.sigma_mm = 0.1;
  AerosolProcess process(settings, 0.025);
  ThicknessField field(0.025);
  const auto all_zero = [](const ThicknessField& f) {
    bool zero = true;
    for (const auto& [tx, ty] : f.tiles().sorted_tiles()) {
      const double* cells = f.tiles().find(tx, ty);
      for (int k = 0; k < ThicknessField::Tiles::kCells; ++k) zero = zero && cells[k] == 0.0;
    }
    return zero && f.total_volume_mm3() == 0.0;
  };
  // footprints along a line crossing several tiles, then a cell far outside their box
  test::drive(
      process, 0.0, 1.0, 1e-3, [](double t) { return Vec3(-1.0 + 3.0 * t, 0.5 - t, 0.0); },
      [](double) { return 1.0; }, [](double) { return 0.0; }, [](double) { return 0.0; });
  field.add(process.field());
  const size_t tiles = field.allocated_tiles();
  ASSERT_GT(tiles, 2u);
  ASSERT_GT(field.total_volume_mm3(), 0.0);
  field.zero();
  EXPECT_TRUE(all_zero(field));
  EXPECT_EQ(field.allocated_tiles(), tiles);
  // the kernel's own box (a process restarted: its field zeroed, its tiles kept)
  process.restart();
  EXPECT_TRUE(all_zero(process.field()));
  test::drive(
      process, 0.0, 0.5, 1e-3, [](double t) { return Vec3(2.0 * t, 0.2, 0.0); },
      [](double) { return 1.0; }, [](double) { return 0.0; }, [](double) { return 0.0; });
  ASSERT_GT(process.field().total_volume_mm3(), 0.0);
  process.restart();
  EXPECT_TRUE(all_zero(process.field()));
  EXPECT_GT(process.field().allocated_tiles(), 0u);
  // single cells, one far beyond the other
  field.add_to_cell(3, 4, 0.001);
  field.add_to_cell(-90, 170, 0.003);
  field.zero();
  EXPECT_TRUE(all_zero(field));
  // a raw write through the tiles
  field.tiles().get_or_create(-2, 1)[17] = 0.5;
  field.zero();
  EXPECT_TRUE(all_zero(field));
}

}  // namespace
}  // namespace depotwin
