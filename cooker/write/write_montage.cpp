// write_montage.cpp — see write_montage.h.
#include "cooker/write/write_montage.h"

namespace ossa::cook {

using flatbuffers::FlatBufferBuilder;
using flatbuffers::Offset;

Offset<fb::SlotNode> write_slot_node(FlatBufferBuilder& fbb, const SlotDef& slot) {
  const auto name = fbb.CreateString(slot.slot);
  const auto group = fbb.CreateString(slot.group);
  Offset<flatbuffers::Vector<const fb::MaskEntry*>> mask_v;
  if (!slot.mask.empty()) {
    std::vector<fb::MaskEntry> mask;
    for (const MaskEntryDef& m : slot.mask) mask.emplace_back(m.joint, m.depth);
    mask_v = fbb.CreateVectorOfStructs(mask);
  }
  return fb::CreateSlotNode(fbb, slot.input, name, group, mask_v, slot.additive, slot.mesh_space_rotation);
}

Offset<flatbuffers::Vector<Offset<fb::Montage>>> write_montages(FlatBufferBuilder& fbb,
                                                                const std::vector<MontageDef>& montages) {
  if (montages.empty()) return {};
  std::vector<Offset<fb::Montage>> out;
  for (const MontageDef& m : montages) {
    std::vector<Offset<fb::MontageTrack>> tracks;
    for (const MontageTrackDef& t : m.tracks) {
      std::vector<fb::MontageSegment> segments;
      for (const MontageSegmentDef& s : t.segments) segments.emplace_back(s.clip, s.start, s.end, s.rate);
      const auto slot = fbb.CreateString(t.slot);
      const auto segments_v = fbb.CreateVectorOfStructs(segments);
      tracks.push_back(fb::CreateMontageTrack(fbb, slot, segments_v));
    }
    std::vector<Offset<fb::MontageSection>> sections;
    for (const MontageSectionDef& s : m.sections)
      sections.push_back(fb::CreateMontageSection(fbb, fbb.CreateString(s.name), s.start, s.next));
    std::vector<Offset<fb::MontageNotify>> notifies;
    for (const MontageNotifyDef& n : m.notifies)
      notifies.push_back(fb::CreateMontageNotify(fbb, fbb.CreateString(n.name), n.time, n.duration,
                                                 static_cast<fb::MontageNotifyKind>(n.kind)));
    const auto name = fbb.CreateString(m.name);
    const auto group = fbb.CreateString(m.group);
    const auto tracks_v = fbb.CreateVector(tracks);
    const auto sections_v = fbb.CreateVector(sections);
    const auto notifies_v =
        notifies.empty() ? Offset<flatbuffers::Vector<Offset<fb::MontageNotify>>>() : fbb.CreateVector(notifies);
    out.push_back(fb::CreateMontage(fbb, name, group, tracks_v, sections_v, notifies_v, m.rate, m.blend_in,
                                    static_cast<fb::MontageCurve>(m.blend_in_curve), m.blend_out,
                                    static_cast<fb::MontageCurve>(m.blend_out_curve), m.blend_out_trigger,
                                    m.root_motion));
  }
  return fbb.CreateVector(out);
}

}  // namespace ossa::cook
