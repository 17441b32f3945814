// Minutes-long random-gesture soak; ctest label `long`, run by hand: ctest -L long
#include "RandomGesture.h"

TEST(Soak, SixtySecondsOfRandomAbsurdGesturesFloat) { rosin::test::randomGestureRun<float>(60.0, 99u); }
TEST(Soak, SixtySecondsOfRandomAbsurdGesturesDouble) { rosin::test::randomGestureRun<double>(60.0, 7u); }
