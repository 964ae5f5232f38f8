// ESLint for the studio's front end (src/tablebot/web/static/js): ES modules in the browser, no globals,
// short functions, and only the import/export forms that tablebot.web.bundle inlines into a replay file.
import js from "@eslint/js";
import globals from "globals";

const BUNDLER_FORMS = [
  { selector: "ExportDefaultDeclaration", message: "export named declarations only (the replay bundler)" },
  { selector: "ExportAllDeclaration", message: "no export * (the replay bundler)" },
  { selector: "ExportNamedDeclaration[source]", message: "no re-exports (the replay bundler)" },
  { selector: "ExportNamedDeclaration[declaration=null]", message: "write export before the declaration" },
  { selector: "ExportNamedDeclaration > VariableDeclaration[kind!='const']", message: "export const only" },
  { selector: "ExportNamedDeclaration > VariableDeclaration[declarations.length>1]", message: "one export a line" },
  { selector: "ImportDefaultSpecifier, ImportNamespaceSpecifier", message: "import { names } only" },
  { selector: "ImportExpression", message: "no dynamic import (the replay page loads nothing)" },
  { selector: "ImportDeclaration[source.value!=/^\\.\\.?\\/[\\w./-]+\\.js$/]", message: "import a relative .js module" },
  { selector: "AssignmentExpression > MemberExpression.left[object.name='window']",
    message: "no globals: export it from a module" },
];

export default [
  { ignores: ["node_modules/**", ".venv/**"] },
  js.configs.recommended,
  {
    files: ["src/tablebot/web/static/js/**/*.js"],
    languageOptions: { ecmaVersion: 2022, sourceType: "module", globals: globals.browser },
    rules: {
      "no-restricted-syntax": ["error", ...BUNDLER_FORMS],
      "no-var": "error",
      "prefer-const": "error",
      eqeqeq: ["error", "always"],
      "no-shadow": "error",
      "no-use-before-define": ["error", { functions: false, classes: true, variables: false }],
      "max-lines-per-function": ["error", { max: 30, skipBlankLines: true, skipComments: true }],
      "max-lines": ["error", { max: 300, skipBlankLines: true, skipComments: true }],
      "max-depth": ["error", 3],
      "max-params": ["error", 5],
      complexity: ["error", 12],
    },
  },
  {
    files: ["eslint.config.js"],
    languageOptions: { sourceType: "module", globals: globals.node },
  },
];
