#pragma once
// Parts and checkpoints of long jobs (`--shard K/N`, `--resume`, `weft merge`). A job is cut into
// units (fiber bake: bands; ray-traced fabric table: incident bins; sweep: views); shard K of N
// owns the contiguous units shard_units(U, K, N). A part file holds some units' results as raw
// doubles (bits kept exactly, so a merge reproduces the unsharded run bit for bit) and a JSON
// header naming the job (command, spec hash, settings, seed), the shard and the units it holds.
//
// File layout: the line "WEFT-PART 1", one line of JSON (the header), then the doubles of every
// unit in the header's order, little-endian, unit_doubles[i] of them for units[i].
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace weft {

// The most shards a job is cut into, and the most units a job has (a ray-traced fabric table has
// 2048 bins at most, a sweep 100 001 views, verify's traces x bins some 10^5): a part file's counts
// are checked against them before anything is sized or looped over by them.
inline constexpr uint32_t kMaxShards = 100000;
inline constexpr uint64_t kMaxJobUnits = uint64_t{1} << 24;

// "K/N" with 0 <= K < N <= kMaxShards: the shard option of a command.
struct Shard {
  uint32_t index = 0, count = 1;
  bool whole() const { return count == 1; }
};
Shard parse_shard(const std::string& text, const std::string& option_name);

// Units [first, last) of shard s of a job of 'units' units.
struct UnitRange {
  uint64_t first = 0, last = 0;
};
UnitRange shard_units(uint64_t units, Shard s);

struct JobPart {
  std::string command;  // "bake fiber", "bake fabric", "sweep"
  nlohmann::json job;   // everything that fixes the result (spec hash, settings, seed)
  uint64_t units_total = 0;
  Shard shard;
  bool checkpoint = false;  // an unfinished run's state: resumable, never merged
  nlohmann::json extra = nlohmann::json::object();  // command-specific, not part of the identity
  std::map<uint64_t, std::vector<double>> units;    // unit -> its results

  // A part of the same job as 'other' (command, job, units_total, shard count).
  bool same_job(const JobPart& other) const;
};

// Written atomically (core/atomic_file.h).
void write_job_part(const std::filesystem::path& path, const JobPart& part);
// Checks the magic line, the header's fields (units_total <= kMaxJobUnits, shards <= kMaxShards)
// and that the payload has exactly the doubles the header promises before allocating them;
// weft::Error naming the file and field otherwise.
JobPart read_job_part(const std::filesystem::path& path);

// Appends / reads raw values of a unit's payload with their exact bits.
void push_u64(std::vector<double>& v, uint64_t x);
uint64_t as_u64(double d);

// Where a run writing 'output' keeps its checkpoint: beside it, ".<name>.weft-checkpoint".
std::filesystem::path checkpoint_path(const std::filesystem::path& output);

// The checkpoint to continue from, if --resume was given and one of this job is there. A
// checkpoint of another job is an error naming it (the user removes it or changes the output).
// An unreadable checkpoint is passed over (the run starts afresh) with a warning appended to
// 'warnings', "<file> is unreadable; starting afresh", for the front end to show.
std::optional<JobPart> load_checkpoint(const std::filesystem::path& output, const JobPart& job,
                                       bool resume, std::vector<std::string>& warnings);

// The content of a job's input files, for its identity: {"<file>": "<FNV-1a 64 hex>"}, so that a
// file changed after a part or checkpoint was written makes it another job. weft::Error naming a
// file that cannot be read.
nlohmann::json input_file_hashes(const std::vector<std::filesystem::path>& files);

// How job 'now' differs from the job 'then' a part or checkpoint was written for, in words for a
// refusal ("the content of scene.gltf differs", "setting 'spp' differs"); "" when they agree.
std::string job_difference(const JobPart& then, const JobPart& now);

// Where a part records, beside its job's identity, the files its job reads that the identity
// holds only by checksum (a ray-traced fabric's fiber tables or specs, a draft its weave options
// name): extra["input_files"], {"<file>": "<FNV-1a 64 hex>"} as input_file_hashes writes them.
// merge_job_parts gathers every part's, and weft merge guards them and checks their content.
inline constexpr const char* kPartInputFilesKey = "input_files";

// The files a merged job recorded (the job's "inputs" and extra's kPartInputFilesKey) whose content
// is no longer what the parts were computed from: "FILE (checksum A in the parts, B now)", one per
// file. A file no longer there is passed over (parts may be merged on another machine).
std::vector<std::string> changed_job_inputs(const JobPart& all);

// Merges parts: all of one job, disjoint, together complete (the first missing shards are
// named); weft::Error naming the file otherwise (a part of another job: the file and "job").
// Returns the job (header of the first part) with every unit.
JobPart merge_job_parts(const std::vector<std::filesystem::path>& paths);

}  // namespace weft
