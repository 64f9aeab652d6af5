// ctest server_openapi: server/openapi.json passes an OpenAPI 3 validator
// (@seriousme/openapi-schema-validator, the JSON schemas of the OpenAPI
// Initiative), and the document the running server serves is that file.
// Usage: node check_openapi.mjs OPENAPI_JSON [SERVED_JSON]
import { readFileSync } from 'node:fs';
import { Validator } from '@seriousme/openapi-schema-validator';

const [file, served] = process.argv.slice(2);
const document = JSON.parse(readFileSync(file, 'utf8'));
const validator = new Validator();
const result = await validator.validate(document);
if (!result.valid) {
  console.error(`${file}: not a valid OpenAPI ${validator.version} document`);
  console.error(JSON.stringify(result.errors, null, 1));
  process.exit(1);
}
// Every $ref resolves (the validator checks the schema, not the links).
const refs = JSON.stringify(document).match(/"\$ref":"[^"]*"/g) || [];
for (const ref of refs) {
  const path = ref.slice(8, -1).replace(/^#\//, '').split('/');
  let node = document;
  for (const key of path) node = node === undefined ? undefined : node[key];
  if (node === undefined) {
    console.error(`${file}: ${ref} resolves to nothing`);
    process.exit(1);
  }
}
if (served && readFileSync(served, 'utf8') !== readFileSync(file, 'utf8')) {
  console.error('the server serves another document than ' + file);
  process.exit(1);
}
console.log(`${file}: valid OpenAPI ${validator.version}, ` +
            `${Object.keys(document.paths).length} paths, ${refs.length} refs`);
