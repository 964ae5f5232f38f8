// One colour per state, the same in the arena's path, the timeline and (by index) every picture.

const PALETTE = ["#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#17becf", "#8c564b", "#e377c2", "#7f7f7f",
  "#bcbd22", "#393b79", "#637939", "#8c6d31", "#843c39", "#7b4173", "#3182bd", "#31a354"];

/** The colour of the state with this index (grey for none). */
export function stateColour(index) {
  if (index === null || index === undefined || index < 0) return "#999999";
  return PALETTE[index % PALETTE.length];
}
