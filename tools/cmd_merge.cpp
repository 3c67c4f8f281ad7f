// weft merge: the parts of a sharded bake or sweep (`--shard K/N`) -> the output the unsharded run
// writes, bit for bit. The parts must be of one job, disjoint and together complete.
#include <filesystem>
#include <string>
#include <vector>

#include "commands.h"
#include "weft/core/error.h"
#include "weft/core/job_part.h"

namespace weft::cli {
void add_merge_command(CLI::App& app, Commands& commands) {
  struct Options {
    std::vector<std::string> parts;
    std::string output, weave_out;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  auto* sub = app.add_subcommand(
      "merge",
      "Merge the parts of a sharded `bake fiber`, `bake fabric --method raytrace`, `sweep` or "
      "`verify` (--shard K/N) into the output of the unsharded run, bit for bit");
  sub->add_option("parts", o->parts, "part files, one per shard, in any order")->required();
  sub->add_option("-o,--output", o->output,
                  "output (.exr table, .csv sweep or verify's report folder)")
      ->required();
  sub->add_option("--weave-out", o->weave_out,
                  "bake fabric parts that carry a weave tally (bake fabric --weave-out): the weave "
                  "table (.exr)");
  sub->add_flag("--json", o->json, "print the command's summary as JSON");
  commands.push_back(
      {sub, [o](const RunLimits& limits) {
         const JobPart all =
             merge_job_parts(std::vector<std::filesystem::path>(o->parts.begin(), o->parts.end()));
         // A verify report is a folder, replaced whole.
         // The parts, and every file the job names (the sweep's and the ray trace's hashed
         // inputs, the fiber tables and specs the parts record, verify's options): what the
         // shards read.
         std::vector<NamedPath> inputs;
         for (const auto& p : o->parts) inputs.push_back({p, "part file"});
         for (const auto* j : {&all.job, &all.extra})
           for (auto& f : json_named_files(*j, "job's input")) inputs.push_back(std::move(f));
         if (!o->weave_out.empty() && all.command != "bake fabric")
           throw Error(o->weave_out, "--weave-out", "only bake fabric parts carry a weave tally");
         if (all.command == "verify")
           validate_output_paths(limits, {}, inputs, {{o->output, "--output"}});
         else
           validate_output_paths(limits, {{o->output, "--output"}, {o->weave_out, "--weave-out"}},
                                 inputs);
         // Parts of files edited since would merge into an output of neither version.
         if (const auto changed = changed_job_inputs(all); !changed.empty()) {
           std::string list;
           for (const auto& c : changed) list += (list.empty() ? "" : "; ") + c;
           throw Error(o->parts.front(), "inputs",
                       "the parts were computed from files that have changed since: " + list +
                           "; run the shards again on the files as they are, or restore them");
         }
         if (all.command == "verify") return merge_verify(all, o->output, o->json);
         if (all.command == "bake fiber") return merge_fiber_bake(all, o->output, o->json);
         if (all.command == "bake fabric")
           return merge_fabric_bake(all, o->output, o->weave_out, o->json);
         if (all.command == "sweep") return merge_sweep(all, o->output, o->json);
         throw Error(o->parts.front(), "command", "unknown command '" + all.command + "'");
       }});
}

}  // namespace weft::cli
