// SPDX-License-Identifier: BSD-3-Clause
// One RunXxx(argc, argv) per subcommand: parse, read, call one library function, write.
#pragma once

namespace tofnav {

int RunConvert(int argc, char** argv);
int RunCorrect(int argc, char** argv);
int RunDemo(int argc, char** argv);
int RunEvaluate(int argc, char** argv);
int RunIdentify(int argc, char** argv);
int RunInfo(int argc, char** argv);
int RunReconstruct(int argc, char** argv);
int RunNavigate(int argc, char** argv);
int RunPivot(int argc, char** argv);
int RunSimulate(int argc, char** argv);
int RunSkin(int argc, char** argv);
int RunRegister(int argc, char** argv);
int RunReport(int argc, char** argv);
int RunServe(int argc, char** argv);
int RunTrack(int argc, char** argv);
int RunToolDefine(int argc, char** argv);
int RunFitMarkerError(int argc, char** argv);

}  // namespace tofnav
