// train_log.jsonl: records round trip; a resumed run cuts the records after its checkpoint.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/io/train_log.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

io::TrainLogRecord step(int iteration) {
  io::TrainLogRecord r;
  r.iteration = iteration;
  r.loss = 0.5 / iteration;
  r.gaussians = 1000 - iteration;
  return r;
}

TEST(TrainLog, RecordsRoundTripAndResumeCutsLaterOnes) {
  test::TempDir dir;
  const std::string path = dir.file("log.jsonl");
  {
    io::TrainLogWriter log(path, -1);
    for (int it = 10; it <= 50; it += 10) log.append(step(it));
    io::TrainLogRecord drop;
    drop.type = "drop";
    drop.iteration = 30;
    drop.removed = 7;
    drop.low_confidence = 3;
    log.append(drop);
  }
  auto records = io::readTrainLog(path);
  ASSERT_EQ(records.size(), 6u);
  EXPECT_EQ(records[5].type, "drop");
  EXPECT_EQ(records[5].removed, 7);
  EXPECT_EQ(records[5].low_confidence, 3);
  EXPECT_DOUBLE_EQ(records[1].loss, 0.5 / 20);
  {
    io::TrainLogWriter resumed(path, 30);  // the checkpoint was at 30: 40 and 50 are trained again
    resumed.append(step(40));
  }
  records = io::readTrainLog(path);
  ASSERT_EQ(records.size(), 5u);  // 10 20 30 drop@30 40
  EXPECT_EQ(records.back().iteration, 40);
  {
    io::TrainLogWriter fresh(path, -1);  // a new run starts an empty log
  }
  EXPECT_TRUE(io::readTrainLog(path).empty());
  test::writeFile(path, "{\"type\":\"step\",\"iteration\":1}\nnot json\n");
  EXPECT_THROW(io::readTrainLog(path), Error);
}

}  // namespace
}  // namespace sadsplat
