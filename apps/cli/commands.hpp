// SPDX-License-Identifier: BSD-3-Clause
// One RunXxx(argc, argv) per subcommand: parse, read, call one library function, write.
#pragma once

#include <string>
#include <string_view>
#include <vector>

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
int RunVerify(int argc, char** argv);
int RunToolDefine(int argc, char** argv);
int RunFitMarkerError(int argc, char** argv);

/// Whether `path` names a command: {"track"}, {"evaluate"}, {"evaluate", "suite"}.
bool IsCommandPath(const std::vector<std::string>& path);
/// Whether `tofnav evaluate <name>` exists.
bool IsEvaluatorName(std::string_view name);

}  // namespace tofnav
