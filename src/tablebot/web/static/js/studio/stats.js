// Counters of what the page received and drew. Nothing on the page reads them: tests and benchmarks
// import this module in the page's context (the same module instance) to measure the live view.
export const stats = { frames: 0, ticks: 0, lastTick: -1, drawMs: 0, messages: 0, analysisMs: [] };
