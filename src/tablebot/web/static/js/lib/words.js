// The page's own words, in English and German (issue 38): every text the studio and the replay page show
// is `t(key, args)` of this catalog, so both languages have the same keys (tests/web/test_studio_i18n.py holds
// them equal) and no English is left in a German page. The words follow ROBO Pro's German interface and
// the command line's German catalog (locale/de/LC_MESSAGES/tablebot.po): Zustand, Folgezustand, Zeile,
// Eingang, Taster, Lampe, Startwert, Akku, Aufzeichnung; a row "schaltet".
// What the server says (errors, findings, reports) it renders itself, in the language the page tells it.
import { DE } from "./words_de.js";
import { EN } from "./words_en.js";

export const LANGUAGES = Object.freeze(["en", "de"]);
const KEPT = "tablebot-studio-lang";  // the switch's choice, in localStorage (kept across visits)
const PARAM = "lang";  // the switch's choice in the address of the page it loads again
/** Not a language: English between markers, so a test finds any text that does not come from the catalog. */
export const PSEUDO = "qps";
export const CATALOGS = Object.freeze({ en: EN, de: DE });
let language = "en";

/** The page's language: the switch's choice (in the address after a switch, else kept), else the studio's
 * --lang (`server`), else the browser's. */
export function chooseLanguage(server) {
  const asked = new URLSearchParams(location.search).get(PARAM);
  if (asked === PSEUDO || LANGUAGES.includes(asked)) return asked;
  let kept = null;
  try { kept = localStorage.getItem(KEPT); } catch { /* storage off: not kept */ }
  if (kept === PSEUDO || LANGUAGES.includes(kept)) return kept;
  if (LANGUAGES.includes(server)) return server;
  for (const wanted of navigator.languages || [navigator.language || ""]) {
    const base = String(wanted).toLowerCase().split("-")[0];
    if (LANGUAGES.includes(base)) return base;
  }
  return "en";
}

/** Speak `lang` from now on (one of LANGUAGES, or PSEUDO); `keep` remembers it (the switch). */
export function setLanguage(lang, keep = false) {
  language = lang === PSEUDO || LANGUAGES.includes(lang) ? lang : "en";
  document.documentElement.lang = language === PSEUDO ? "en" : language;
  if (keep) try { localStorage.setItem(KEPT, language); } catch { /* storage off: for this page only */ }
}

/** The language in use. */
export function currentLanguage() { return language; }

// Intl's formats, made once per language and options (a frame's status line asks for several numbers a tick)
const formats = new Map();

function format(options) {
  const lang = language === PSEUDO ? "en" : language;
  const key = lang + JSON.stringify(options);
  if (!formats.has(key)) formats.set(key, new Intl.NumberFormat(lang, { useGrouping: false, ...options }));
  return formats.get(key);
}

/** `value` as the page's language writes a number for a person (1,25 in German, 1.25 in English; no thousands
 * grouping, as the command line's tablebot.i18n.number): every number the page draws comes through here, so
 * none is written in English by a toFixed. At most `most` decimals, at least `least` (trailing zeros dropped
 * down to it). Only for text: a cell's value and what is saved stay as the table file has them. */
export function number(value, most = 2, least = 0) {
  return format({ maximumFractionDigits: most, minimumFractionDigits: least }).format(value);
}

/** A fraction (0.5) as a whole percentage the page's language writes (50 % in German, 50% in English). */
export function percent(fraction) {
  return format({ style: "percent", maximumFractionDigits: 0 }).format(fraction);
}

/** The hour and minute of `ms` (since the epoch) as the page's language writes a time of day (14:05). */
export function clock(ms) {
  const lang = language === PSEUDO ? "en" : language;
  return new Date(ms).toLocaleTimeString(lang, { hour: "2-digit", minute: "2-digit" });
}

/** The text of `key` in the language in use, its `{name}` fields filled from `args`. */
export function t(key, args = {}) {
  const catalog = language === "de" ? DE : EN;
  if (!Object.hasOwn(catalog, key)) throw new Error(`no word ${key} in the page's catalog`);
  const text = catalog[key].replace(/\{(\w+)\}/g, (whole, name) => (Object.hasOwn(args, name) ? String(args[name]) : whole));
  return language === PSEUDO ? `⟦${text}⟧` : text;
}

// the page's HTML names its words by key: data-t (the text), data-t-title, data-t-aria, data-t-placeholder
const ATTRIBUTES = [["tTitle", "title"], ["tAria", "aria-label"], ["tPlaceholder", "placeholder"]];

/** Every element under `root` that names a word, given it in the language in use. */
export function translatePage(root = document) {
  for (const el of root.querySelectorAll("[data-t]")) el.textContent = t(el.dataset.t);
  for (const [data, attribute] of ATTRIBUTES) {
    const selector = "[data-" + data.replace(/[A-Z]/g, (c) => "-" + c.toLowerCase()) + "]";
    for (const el of root.querySelectorAll(selector)) el.setAttribute(attribute, t(el.dataset[data]));
  }
}

/** The switch: a select of the languages (each named in itself); a change is kept and reloads the page, so
 * every word (and the server's, which it renders for this tab's language) is said again in the new one. */
export function wireSwitch(select) {
  select.replaceChildren(...LANGUAGES.map((lang) => {
    const option = document.createElement("option");
    option.value = lang;
    const name = CATALOGS[lang]["language.name"];  // each language named in itself
    option.textContent = language === PSEUDO ? `⟦${name}⟧` : name;
    return option;
  }));
  select.value = language === PSEUDO ? "en" : language;
  select.addEventListener("change", () => {
    setLanguage(select.value, true);
    // The page comes again with the choice in its address too: localStorage's write travels to the browser's
    // store on its own, and a reloaded page read the old language before it got there (seen on a busy machine).
    const again = new URL(location.href);
    again.searchParams.set(PARAM, select.value);
    location.replace(again.href);
  });
}
